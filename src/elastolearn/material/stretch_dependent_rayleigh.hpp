#pragma once
/// \file Rayleigh damping whose coefficients are functions of the element's largest principal
/// stretch σ₁ (paper 000 §7.2.2, "strain-dependent damping": α₁ a polynomial of the stretch; a
/// spline serves an edited curve).
#include <elastolearn/material/damping_model.hpp>
#include <elastolearn/material/stretch_curve.hpp>

namespace elastolearn::material {

/// α₀(σ₁) [1/s] and α₁(σ₁) [s], each a monotone cubic spline (constant outside its knots) or a
/// polynomial in σ₁ − 1 (clamped at zero).
class StretchDependentRayleigh final : public DampingModel {
  public:
  /// Throws InputError(where, ...) if a spline has a negative knot value (the monotone spline
  /// stays within its knot values, so a non-negative spline gives non-negative damping).
  StretchDependentRayleigh(
      StretchCurve alpha0, StretchCurve alpha1, const std::string& where = "damping");
  std::string name() const override { return "stretch_dependent_rayleigh"; }
  RayleighCoefficients coefficients(double max_stretch) const override;
  bool is_constant() const override { return false; }
  std::unique_ptr<DampingModel> clone() const override;

  /// dα₀/dσ₁ and dα₁/dσ₁ at σ₁ (for integrators that differentiate the damping force fully).
  RayleighCoefficients coefficient_derivatives(double max_stretch) const;
  const StretchCurve& alpha0() const { return m_alpha0; }
  const StretchCurve& alpha1() const { return m_alpha1; }

  private:
  StretchCurve m_alpha0, m_alpha1;
};

} // namespace elastolearn::material
