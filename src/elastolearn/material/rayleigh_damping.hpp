#pragma once
/// \file Constant Rayleigh damping f_d = −(α₀ M + α₁ K(x)) v (paper 000 §4.1).
#include <elastolearn/material/damping_model.hpp>

namespace elastolearn::material {

/// Constant coefficients α₀ [1/s] and α₁ [s] for every element.
class RayleighDamping final : public DampingModel {
  public:
  /// Throws InputError(where, ...) if a coefficient is negative or not finite.
  RayleighDamping(double alpha0, double alpha1, const std::string& where = "damping");
  std::string name() const override { return "rayleigh"; }
  RayleighCoefficients coefficients(double) const override { return m_coefficients; }
  bool is_constant() const override { return true; }
  std::unique_ptr<DampingModel> clone() const override;

  private:
  RayleighCoefficients m_coefficients;
};

} // namespace elastolearn::material
