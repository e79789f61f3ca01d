#include <elastolearn/core/error.hpp>
#include <elastolearn/material/damping_model.hpp>

namespace elastolearn::material {

std::string to_string(DampingTangent tangent) {
  switch (tangent) {
  case DampingTangent::FlipFree:
    return "flip-free";
  case DampingTangent::Exact:
    return "exact";
  }
  ELASTOLEARN_CHECK(false, "unknown DampingTangent " + std::to_string(static_cast<int>(tangent)));
  return {};
}

DampingTangent damping_tangent_from_string(std::string_view name, const std::string& where) {
  std::string valid;
  for (DampingTangent t : all_damping_tangents) {
    const std::string s = to_string(t);
    if (s == name)
      return t;
    valid += (valid.empty() ? "" : ", ") + s;
  }
  throw InputError(
      where, "unknown damping tangent '" + std::string(name) + "' (valid: " + valid + ")");
}

} // namespace elastolearn::material
