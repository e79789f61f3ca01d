#include <elastolearn/core/error.hpp>

namespace elastolearn {

InputError::InputError(std::string where, const std::string& what)
    : std::runtime_error(where.empty() ? what : where + ": " + what)
    , m_where(std::move(where)) { }

void FieldErrors::operator()(const std::string& field, const std::string& what) const {
  throw InputError(m_group + ("." + field), what);
}

void throw_internal_error(
    const char* condition, const char* file, int line, const std::string& message) {
  throw InternalError(std::string(file) + ":" + std::to_string(line) + ": check '" + condition
      + "' failed: " + message);
}

} // namespace elastolearn
