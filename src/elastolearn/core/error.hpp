#pragma once
/// \file Error tiers (as in Drake): `assert` for hot-path invariants, `ELASTOLEARN_CHECK` for
/// impossible states (always on), and `InputError` for bad user input — it names the file, field
/// or line and the offending value. The app catches InputError, prints one line, exits non-zero.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace elastolearn {

/// Bad user input: unreadable file, wrong format, NaN, out-of-range index, invalid field.
/// `where` is the file (optionally with ":line") or the JSON field path; `what` says what is wrong.
class InputError : public std::runtime_error {
  public:
  InputError(std::string where, const std::string& what);
  /// The file/field/line the error refers to.
  const std::string& where() const noexcept { return m_where; }

  private:
  std::string m_where;
};

/// Throws InputError for the fields of one group of inputs (an options struct, a file section):
/// `where` is "<group>.<field>". A file that validates a group declares one, named for its group
/// (unique within its library: a unity build compiles several files as one),
///   constexpr FieldErrors pod_error("pod");
/// and reports a bad field with `pod_error("max_modes", "must be at least 1, got 0")`.
class FieldErrors {
  public:
  constexpr explicit FieldErrors(const char* group)
      : m_group(group) { }
  /// Throws InputError("<group>.<field>", what).
  [[noreturn]] void operator()(const std::string& field, const std::string& what) const;

  private:
  const char* m_group;
};

/// Internal logic error: an invariant that can only fail through a bug.
class InternalError : public std::logic_error {
  public:
  using std::logic_error::logic_error;
};

[[noreturn]] void throw_internal_error(
    const char* condition, const char* file, int line, const std::string& message);

/// `text` made safe to print as one terminal line: control characters (newlines, escape
/// sequences) and bytes that are not UTF-8 become `\xNN`, and it is cut after about `max_bytes`
/// bytes with "...". Messages quote input files, and a hostile file's bytes must neither break
/// the one-line error nor reach the terminal raw.
std::string printable_line(std::string_view text, std::size_t max_bytes = 400);

} // namespace elastolearn

/// Always-on check for states that should be impossible.
#define ELASTOLEARN_CHECK(cond, msg)                                                               \
  do {                                                                                             \
    if (!(cond))                                                                                   \
      ::elastolearn::throw_internal_error(#cond, __FILE__, __LINE__, (msg));                       \
  } while (false)
