#include <elastolearn/core/error.hpp>

namespace elastolearn {

InputError::InputError(std::string where, const std::string& what)
    : std::runtime_error(where.empty() ? what : where + ": " + what)
    , m_where(std::move(where)) { }

void FieldErrors::operator()(const std::string& field, const std::string& what) const {
  throw InputError(m_group + ("." + field), what);
}

std::string printable_line(std::string_view text, std::size_t max_bytes) {
  std::string out;
  const auto escape = [&](unsigned char c) {
    static const char* hex = "0123456789abcdef";
    out += "\\x";
    out += hex[c >> 4];
    out += hex[c & 15];
  };
  for (std::size_t i = 0; i < text.size();) {
    if (out.size() >= max_bytes) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      escape(c);
      ++i;
      continue;
    }
    if (c < 0x80) {
      out += char(c);
      ++i;
      continue;
    }
    // A UTF-8 sequence: a lead byte 110xxxxx/1110xxxx/11110xxx and its continuation bytes.
    const std::size_t length = (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
    bool valid = length > 0 && i + length <= text.size();
    for (std::size_t k = 1; valid && k < length; ++k)
      valid = (static_cast<unsigned char>(text[i + k]) >> 6) == 0x2;
    if (valid) {
      out.append(text.substr(i, length));
      i += length;
    } else {
      escape(c);
      ++i;
    }
  }
  return out;
}

void throw_internal_error(
    const char* condition, const char* file, int line, const std::string& message) {
  throw InternalError(std::string(file) + ":" + std::to_string(line) + ": check '" + condition
      + "' failed: " + message);
}

} // namespace elastolearn
