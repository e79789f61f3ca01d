#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/stretch_dependent_rayleigh.hpp>

namespace elastolearn::material {

namespace {
void check_non_negative(const StretchCurve& s, const std::string& where) {
  if (s.lower_bound() < 0)
    throw InputError(where,
        "Rayleigh coefficient spline must be non-negative, got a knot value "
            + to_text(s.lower_bound()));
}
} // namespace

StretchDependentRayleigh::StretchDependentRayleigh(
    StretchCurve alpha0, StretchCurve alpha1, const std::string& where)
    : m_alpha0(std::move(alpha0))
    , m_alpha1(std::move(alpha1)) {
  check_non_negative(m_alpha0, where + ".alpha0");
  check_non_negative(m_alpha1, where + ".alpha1");
}

RayleighCoefficients StretchDependentRayleigh::coefficients(double max_stretch) const {
  return { m_alpha0.value(max_stretch), m_alpha1.value(max_stretch) };
}

RayleighCoefficients StretchDependentRayleigh::coefficient_derivatives(double max_stretch) const {
  return { m_alpha0.derivative(max_stretch), m_alpha1.derivative(max_stretch) };
}

std::unique_ptr<DampingModel> StretchDependentRayleigh::clone() const {
  return std::make_unique<StretchDependentRayleigh>(*this);
}

} // namespace elastolearn::material
