#include <elastolearn/core/format.hpp>

namespace elastolearn {

std::string to_text_exact(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

} // namespace elastolearn
