#include <elastolearn/mesh/line_reader.hpp>

#include <elastolearn/core/atomic_file.hpp>

#include <cctype>
#include <charconv>
#include <cmath>

namespace elastolearn::mesh {

LineReader::LineReader(const std::filesystem::path& path, char comment_char)
    : m_name(path.string())
    , m_text(read_text_file(path))
    , m_comment(comment_char) { }

LineReader::LineReader(std::string name, std::string text, char comment_char)
    : m_name(std::move(name))
    , m_text(std::move(text))
    , m_comment(comment_char) { }

bool LineReader::next() {
  while (m_pos < m_text.size()) {
    std::size_t end = m_text.find('\n', m_pos);
    if (end == std::string::npos)
      end = m_text.size();
    std::string_view line(m_text.data() + m_pos, end - m_pos);
    m_pos = end < m_text.size() ? end + 1 : end;
    ++m_line_number;
    if (m_comment != '\0') {
      const auto c = line.find(m_comment);
      if (c != std::string_view::npos)
        line = line.substr(0, c);
    }
    m_tokens.clear();
    const auto separator = [&](char ch) {
      return std::isspace(static_cast<unsigned char>(ch)) || (m_commas && ch == ',');
    };
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && separator(line[i]))
        ++i;
      std::size_t j = i;
      while (j < line.size() && !separator(line[j]))
        ++j;
      if (j > i)
        m_tokens.push_back(line.substr(i, j - i));
      i = j;
    }
    if (!m_tokens.empty()) {
      m_line = line;
      return true;
    }
  }
  m_tokens.clear();
  m_line = {};
  return false;
}

void LineReader::require(std::string_view what) {
  if (!next())
    throw InputError(
        where(), "unexpected end of file (truncated?) while reading " + std::string(what));
}

void LineReader::require_tokens(std::size_t n, std::string_view what) const {
  if (m_tokens.size() < n)
    fail("expected " + std::to_string(n) + " values for " + std::string(what) + ", found "
        + std::to_string(m_tokens.size()) + " in '" + std::string(m_line) + "'");
}

std::string LineReader::where() const {
  // Before the first line (an empty file) there is no line to name.
  return m_line_number > 0 ? m_name + ":" + std::to_string(m_line_number) : m_name;
}

void LineReader::fail(const std::string& message) const {
  throw InputError(where(), message);
}

long long LineReader::integer(std::size_t i, std::string_view what) const {
  require_tokens(i + 1, what);
  long long v = 0;
  if (!parse_integer(m_tokens[i], v))
    fail("invalid integer '" + std::string(m_tokens[i]) + "' for " + std::string(what));
  return v;
}

double LineReader::real(std::size_t i, std::string_view what) const {
  require_tokens(i + 1, what);
  double v = 0;
  if (!parse_real(m_tokens[i], v))
    fail("invalid number '" + std::string(m_tokens[i]) + "' for " + std::string(what));
  if (!std::isfinite(v))
    fail("non-finite value '" + std::string(m_tokens[i]) + "' for " + std::string(what));
  return v;
}

bool parse_integer(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+')
    token.remove_prefix(1);
  const auto r = std::from_chars(token.data(), token.data() + token.size(), value);
  return r.ec == std::errc() && r.ptr == token.data() + token.size();
}

bool parse_real(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+')
    token.remove_prefix(1);
  const auto r = std::from_chars(token.data(), token.data() + token.size(), value);
  return r.ec == std::errc() && r.ptr == token.data() + token.size();
}

} // namespace elastolearn::mesh
