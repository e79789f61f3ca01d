#pragma once
/// \file Base64 (RFC 4648, standard alphabet, '=' padding): how a report inlines binary data
/// (PNG plots, float arrays) into one self-contained HTML file.
#include <cstddef>
#include <span>
#include <string>

namespace elastolearn {

/// The base64 text of `bytes` (4 characters per 3 bytes, padded).
std::string base64_encode(std::span<const std::byte> bytes);

/// The same for text or any byte string.
std::string base64_encode(const std::string& bytes);

} // namespace elastolearn
