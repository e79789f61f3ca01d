// Stanford PLY surfaces, ASCII and binary little-endian.
#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/surface_readers.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace elastolearn::mesh {

namespace {

enum class PlyType { i8, u8, i16, u16, i32, u32, f32, f64 };

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::u8;
  PlyType type = PlyType::f32;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> props;
};

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

/// Reads values one at a time from the body, ASCII (token by token within one element line) or
/// binary little-endian.
class PlyBody {
  public:
  PlyBody(LineReader& in, bool binary)
      : m_in(in)
      , m_binary(binary)
      , m_pos(in.offset_after_line()) { }

  void begin_element(const std::string& what) {
    m_what = what;
    if (!m_binary) {
      m_in.require(what);
      m_token = 0;
    }
  }

  double value(PlyType type) {
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

  std::string where() const { return m_binary ? m_in.name() : m_in.where(); }

  private:
  template <int N, typename U> U bytes() {
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

  LineReader& m_in;
  bool m_binary;
  std::size_t m_pos;
  std::size_t m_token = 0;
  std::string m_what;
};

} // namespace

SurfaceMesh read_ply(const std::filesystem::path& path) {
  LineReader in(path, '\0');
  in.require("the PLY header");
  if (in[0] != "ply")
    in.fail("not a PLY file (missing 'ply' magic)");
  bool binary = false;
  std::vector<PlyElement> elements;
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
        binary = false;
      else if (in[1] == "binary_little_endian")
        binary = true;
      else
        in.fail("unsupported PLY format '" + std::string(in[1])
            + "' (ascii and binary_little_endian only)");
    } else if (key == "element") {
      in.require_tokens(3, "element");
      const long long n = in.integer(2, "element count");
      if (n < 0 || n >= (1LL << 31))
        in.fail("invalid element count " + std::to_string(n));
      elements.push_back({ std::string(in[1]), n, {} });
    } else if (key == "property") {
      if (elements.empty())
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
      elements.back().props.push_back(p);
    } else {
      in.fail("unexpected PLY header line '" + std::string(in.line()) + "'");
    }
  }

  SurfaceBuilder builder(path.string());
  PlyBody body(in, binary);
  std::vector<long long> poly;
  bool have_faces_element = false;
  for (const PlyElement& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    have_faces_element |= is_face;
    for (long long i = 0; i < e.count; ++i) {
      body.begin_element(e.name + " " + std::to_string(i) + " of " + std::to_string(e.count));
      double xyz[3] = { 0, 0, 0 };
      int found = 0;
      for (const PlyProperty& p : e.props) {
        if (!p.list) {
          const double v = body.value(p.type);
          const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
          if (is_vertex && axis >= 0) {
            if (!std::isfinite(v))
              throw InputError(body.where(),
                  "non-finite " + p.name + " coordinate of vertex " + std::to_string(i));
            xyz[axis] = v;
            found |= 1 << axis;
          }
          continue;
        }
        const double count = body.value(p.count_type);
        if (!(count >= 0 && count <= 1e6))
          throw InputError(body.where(), "invalid list length in " + e.name);
        const bool indices = is_face && (p.name == "vertex_indices" || p.name == "vertex_index");
        poly.clear();
        for (int k = 0; k < static_cast<int>(count); ++k) {
          const double v = body.value(p.type);
          if (indices)
            poly.push_back(static_cast<long long>(v));
        }
        if (indices)
          builder.add_polygon(poly, body.where() + " (face " + std::to_string(i) + ")");
      }
      if (is_vertex) {
        if (found != 7)
          throw InputError(path.string(), "PLY vertex element lacks x, y or z");
        builder.add_vertex(xyz[0], xyz[1], xyz[2]);
      }
    }
  }
  if (!have_faces_element)
    throw InputError(path.string(), "PLY file has no face element");
  return builder.finish();
}

} // namespace elastolearn::mesh
