#include <elastolearn/mesh/ply_reader.hpp>

#include <bit>
#include <cstdint>

namespace elastolearn::mesh {

namespace {

PlyType parse_type(const LineReader& in, std::string_view t) {
  if (t == "char" || t == "int8")
    return PlyType::i8;
  if (t == "uchar" || t == "uint8")
    return PlyType::u8;
  if (t == "short" || t == "int16")
    return PlyType::i16;
  if (t == "ushort" || t == "uint16")
    return PlyType::u16;
  if (t == "int" || t == "int32")
    return PlyType::i32;
  if (t == "uint" || t == "uint32")
    return PlyType::u32;
  if (t == "float" || t == "float32")
    return PlyType::f32;
  if (t == "double" || t == "float64")
    return PlyType::f64;
  in.fail("unknown PLY property type '" + std::string(t) + "'");
}

} // namespace

PlyReader::PlyReader(const std::filesystem::path& path)
    : m_in(path, '\0') {
  LineReader& in = m_in;
  in.require("the PLY header");
  if (in[0] != "ply")
    in.fail("not a PLY file (missing 'ply' magic)");
  for (;;) {
    in.require("the PLY header (no end_header)");
    const std::string_view key = in[0];
    if (key == "end_header")
      break;
    if (key == "comment" || key == "obj_info")
      continue;
    if (key == "format") {
      in.require_tokens(2, "format");
      if (in[1] == "ascii")
        m_binary = false;
      else if (in[1] == "binary_little_endian")
        m_binary = true;
      else
        in.fail("unsupported PLY format '" + std::string(in[1])
            + "' (ascii and binary_little_endian only)");
    } else if (key == "element") {
      in.require_tokens(3, "element");
      const long long n = in.integer(2, "element count");
      if (n < 0 || n >= (1LL << 31))
        in.fail("invalid element count " + std::to_string(n));
      m_elements.push_back({ std::string(in[1]), n, {} });
    } else if (key == "property") {
      if (m_elements.empty())
        in.fail("property before any element");
      PlyProperty p;
      if (in.size() >= 2 && in[1] == "list") {
        in.require_tokens(5, "list property");
        p.list = true;
        p.count_type = parse_type(in, in[2]);
        p.type = parse_type(in, in[3]);
        p.name = in[4];
      } else {
        in.require_tokens(3, "property");
        p.type = parse_type(in, in[1]);
        p.name = in[2];
      }
      m_elements.back().props.push_back(p);
    } else {
      in.fail("unexpected PLY header line '" + std::string(in.line()) + "'");
    }
  }
  m_pos = in.offset_after_line();
}

void PlyReader::begin_record(const std::string& what) {
  m_what = what;
  if (!m_binary) {
    m_in.require(what);
    m_token = 0;
  }
}

template <int N, typename U> U PlyReader::bytes() {
  const std::string& data = m_in.text();
  if (m_pos + N > data.size())
    throw InputError(m_in.name(), "truncated binary data while reading " + m_what);
  U v = 0;
  for (int i = 0; i < N; ++i)
    v |= static_cast<U>(static_cast<unsigned char>(data[m_pos + static_cast<std::size_t>(i)]))
        << (8 * i);
  m_pos += N;
  return v;
}

double PlyReader::value(PlyType type) {
  if (!m_binary) {
    if (m_token >= m_in.size())
      m_in.fail("too few values for " + m_what);
    double v = 0;
    if (!parse_real(m_in[m_token], v))
      m_in.fail("invalid number '" + std::string(m_in[m_token]) + "' in " + m_what);
    ++m_token;
    return v;
  }
  switch (type) {
  case PlyType::i8:
    return static_cast<double>(std::bit_cast<std::int8_t>(bytes<1, std::uint8_t>()));
  case PlyType::u8:
    return bytes<1, std::uint8_t>();
  case PlyType::i16:
    return std::bit_cast<std::int16_t>(bytes<2, std::uint16_t>());
  case PlyType::u16:
    return bytes<2, std::uint16_t>();
  case PlyType::i32:
    return std::bit_cast<std::int32_t>(bytes<4, std::uint32_t>());
  case PlyType::u32:
    return bytes<4, std::uint32_t>();
  case PlyType::f32:
    return std::bit_cast<float>(bytes<4, std::uint32_t>());
  case PlyType::f64:
    return std::bit_cast<double>(bytes<8, std::uint64_t>());
  }
  return 0;
}

void PlyReader::skip(const PlyProperty& p) {
  if (!p.list) {
    value(p.type);
    return;
  }
  const double count = value(p.count_type);
  if (!(count >= 0 && count <= 1e6))
    throw InputError(where(), "invalid list length in " + m_what);
  for (int k = 0; k < static_cast<int>(count); ++k)
    value(p.type);
}

std::string PlyReader::where() const {
  return m_binary ? m_in.name() : m_in.where();
}

} // namespace elastolearn::mesh
