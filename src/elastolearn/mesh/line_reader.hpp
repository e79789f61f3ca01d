#pragma once
/// \file Line-oriented tokenizer shared by the mesh readers (TetGen, Gmsh, Vega, OBJ, OFF, PLY,
/// STL ASCII). Every parse error it raises is an InputError whose `where` is "file:line".
#include <elastolearn/core/error.hpp>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace elastolearn::mesh {

/// Splits a whole text (a file read at once) into lines and whitespace-separated tokens.
/// Comments (from `comment_char` to the end of the line) and blank lines are skipped by
/// `next()`; line numbers are 1-based and refer to the original file.
class LineReader {
  public:
  /// Reads `path` completely. Throws InputError naming the path if it cannot be read.
  /// `comment_char` = '\0' disables comment stripping.
  explicit LineReader(const std::filesystem::path& path, char comment_char = '#');
  /// Wraps text already in memory (e.g. the ASCII header of a binary file); `name` for errors.
  LineReader(std::string name, std::string text, char comment_char = '#');

  /// Also split tokens at commas (Vega files may write "1, 0.0, 1.0, 2.0").
  void split_on_commas(bool on) { m_commas = on; }
  /// Advances to the next non-empty line; false at end of file.
  bool next();
  /// Like next(), but a missing line is an error: "unexpected end of file while reading <what>".
  void require(std::string_view what);
  /// Tokens of the current line.
  const std::vector<std::string_view>& tokens() const { return m_tokens; }
  std::size_t size() const { return m_tokens.size(); }
  std::string_view operator[](std::size_t i) const { return m_tokens[i]; }
  /// Throws unless the current line has at least `n` tokens.
  void require_tokens(std::size_t n, std::string_view what) const;
  /// The current line, untokenized (without comment).
  std::string_view line() const { return m_line; }
  /// 1-based line number of the current line.
  int line_number() const { return m_line_number; }
  /// "file:line" of the current line ("file" before the first line).
  std::string where() const;
  /// The file name used in errors.
  const std::string& name() const { return m_name; }
  /// Byte offset just past the current line (to continue with binary data after a header).
  std::size_t offset_after_line() const { return m_pos; }
  /// The whole text.
  const std::string& text() const { return m_text; }

  /// Parses token `i` of the current line as an integer; error names `what` and the token.
  long long integer(std::size_t i, std::string_view what) const;
  /// Parses token `i` as a finite double; NaN/inf and junk are errors naming `what`.
  double real(std::size_t i, std::string_view what) const;
  /// Throws InputError(where(), message).
  [[noreturn]] void fail(const std::string& message) const;

  private:
  std::string m_name;
  std::string m_text;
  char m_comment;
  bool m_commas = false;
  std::size_t m_pos = 0;
  int m_line_number = 0;
  std::string_view m_line;
  std::vector<std::string_view> m_tokens;
};

/// Parses a whole token as a long long; false if it is not exactly an integer.
bool parse_integer(std::string_view token, long long& value);
/// Parses a whole token as a double (accepts "nan"/"inf" spellings; caller checks finiteness).
bool parse_real(std::string_view token, double& value);

} // namespace elastolearn::mesh
