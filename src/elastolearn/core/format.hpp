#pragma once
/// \file Numbers as text for messages (InputError, reports): one spelling for the whole library.
#include <sstream>
#include <string>

namespace elastolearn {

/// `v` as `std::ostream << v` writes it: integers exactly, floating point with 6 significant
/// digits as printf's %g (1e-09, 0.25, 3.5e+06), where std::to_string's six fixed decimals
/// would print 1e-9 as 0.000000.
template <typename T> std::string to_text(const T& v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// `v` with 17 significant digits, enough to read back the same double: for values a message
/// compares (a time step that differs from another by round-off must not print equal).
std::string to_text_exact(double v);

/// `text` with &, <, >, " and ' replaced by entities: safe as HTML or XML text and as a quoted
/// attribute value (the report's page, VTU/PVD files).
std::string html_escape(const std::string& text);

} // namespace elastolearn
