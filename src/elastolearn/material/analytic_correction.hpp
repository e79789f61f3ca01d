#pragma once
/// \file A closed-form material correction N(F̂, Ḟ̂) (paper 000 Eq. 1) for testing the correction
/// hook end to end before the learned corrections (RBF, network) exist.
#include <elastolearn/material/correction.hpp>

namespace elastolearn::material {

/// Nᵢ = a (σᵢ − 1)³ + b ḟᵢ (1 + c Σⱼ(σⱼ − 1)²):
/// a cubic stiffening/softening in each stretch (a [Pa]) plus a stretch-dependent viscous term
/// (b [Pa·s] at rest, growing by the factor 1 + c‖σ − 1‖², c dimensionless).
/// Smooth and symmetric under any simultaneous permutation of (σ, ḟ); zero at rest with ḟ = 0.
/// ∂Nᵢ/∂σₖ = 3a(σᵢ − 1)² δᵢₖ + 2 b c ḟᵢ (σₖ − 1),  ∂Nᵢ/∂ḟₖ = b (1 + c Σⱼ(σⱼ − 1)²) δᵢₖ.
class AnalyticCorrection final : public Correction {
  public:
  struct Parameters {
    double a = 0; ///< cubic stretch coefficient [Pa]
    double b = 0; ///< viscous coefficient [Pa·s]
    double c = 0; ///< stretch dependence of the viscous term [-]
  };
  /// Throws InputError if a parameter is not finite.
  explicit AnalyticCorrection(const Parameters& parameters);
  std::string name() const override { return "analytic"; }
  Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const override;
  void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  std::unique_ptr<Correction> clone() const override;
  const Parameters& parameters() const { return m_p; }

  private:
  Parameters m_p;
};

} // namespace elastolearn::material
