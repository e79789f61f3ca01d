#include <elastolearn/core/base64.hpp>

namespace elastolearn {

std::string base64_encode(std::span<const std::byte> bytes) {
  static constexpr char alphabet[]
      = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const unsigned v = (std::to_integer<unsigned>(bytes[i]) << 16)
        | (std::to_integer<unsigned>(bytes[i + 1]) << 8) | std::to_integer<unsigned>(bytes[i + 2]);
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += alphabet[(v >> 6) & 63];
    out += alphabet[v & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    unsigned v = std::to_integer<unsigned>(bytes[i]) << 16;
    if (rest == 2)
      v |= std::to_integer<unsigned>(bytes[i + 1]) << 8;
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += rest == 2 ? alphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string base64_encode(const std::string& bytes) {
  return base64_encode(std::as_bytes(std::span(bytes.data(), bytes.size())));
}

} // namespace elastolearn
