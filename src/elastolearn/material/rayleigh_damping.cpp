#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>

#include <cmath>

namespace elastolearn::material {

namespace {
void check_coefficient(double value, const std::string& where) {
  if (!std::isfinite(value) || value < 0)
    throw InputError(
        where, "Rayleigh coefficient must be finite and non-negative, got " + to_text(value));
}
} // namespace

RayleighDamping::RayleighDamping(double alpha0, double alpha1, const std::string& where)
    : m_coefficients { alpha0, alpha1 } {
  check_coefficient(alpha0, where + ".alpha0");
  check_coefficient(alpha1, where + ".alpha1");
}

std::unique_ptr<DampingModel> RayleighDamping::clone() const {
  return std::make_unique<RayleighDamping>(*this);
}

} // namespace elastolearn::material
