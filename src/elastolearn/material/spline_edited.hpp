#pragma once
/// \file Spline-edited materials after Xu, Sin, Zhu & Barbič 2015 ("Nonlinear material design
/// using principal stretches"), used as "user designed" ground truths (paper 000 §7, Fig. 10).
#include <elastolearn/material/elastic_model.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/material/spline.hpp>

#include <memory>
#include <string>
#include <string_view>

namespace elastolearn::material {

/// Where the edit acts: tension (σ > 1) or compression (σ < 1).
enum class SplineEditRegion { Tension, Compression };

/// "tension", "compression".
std::string to_string(SplineEditRegion region);
/// Inverse of to_string; throws InputError(where, ...) listing the valid names.
SplineEditRegion spline_edit_region_from_string(
    std::string_view name, const std::string& where = "spline edit region");

/// A base model written in Xu et al.'s separable form Ψ = Σᵢ f(σᵢ) + C(σ), whose 1-D term
/// f′ is multiplied by a user spline s(σ):
///   Ψ_edit(σ) = Ψ_base(σ) + Σᵢ Δ(σᵢ),  Δ(x) = ∫₁ˣ (s(t) − 1) f′(t) dt,
///   P̂ᵢ = P̂_base,ᵢ + (s(σᵢ) − 1) f′(σᵢ),  ∂P̂ᵢ/∂σᵢ += s′(σᵢ) f′(σᵢ) + (s(σᵢ) − 1) f″(σᵢ).
/// Bases (f, the rest C):
///   - neo-Hookean: f(x) = μ/2 (x² − 1) (Xu et al. Table 1), C = −μ L + λ/2 L² (NeoHookeanModel);
///   - corotated:  f(x) = μ (x − 1)²,                     C = λ/2 (Σ(σᵢ − 1))².
/// The spline's knots must lie inside the region (tension: x₀ ≥ 1; compression: x_{n−1} ≤ 1) and
/// its knot nearest the rest stretch must have value 1. With constant extrapolation this makes
/// s ≡ 1 outside the region and at σ = 1, and s is C¹, so P̂ is C¹ and vanishes at rest.
/// Δ is integrated with 3-point Gauss–Legendre on each knot interval, exact for the quartic
/// integrand (cubic s times linear f′), so P̂ = ∂Ψ/∂σ to rounding.
/// Note: the edit scales f′, not the total stress. For the corotated base f′ = 2μ(σ − 1), so
/// s > 1 stiffens either region; for neo-Hookean f′ = μσ > 0, so s > 1 stiffens tension while in
/// compression s < 1 stiffens (less of the positive f′ offsets the compressive ln term).
class SplineEditedModel final : public ElasticModel {
  public:
  /// Throws InputError(where, ...) if `base` is not Corotated or NeoHookean, if a knot lies
  /// outside the region, if the knot nearest σ = 1 does not have value 1, or if a knot value is
  /// not positive.
  SplineEditedModel(ElasticModelType base, const Lame& lame, SplineEditRegion region,
      CubicSpline spline, const std::string& where = "spline_edited");
  std::string name() const override { return "spline_edited"; }
  double energy(const Vec3& stretches) const override;
  Vec3 principal_stress(const Vec3& stretches) const override;
  Mat3 principal_stress_derivative(const Vec3& stretches) const override;
  std::unique_ptr<ElasticModel> clone() const override;

  ElasticModelType base_type() const { return m_base_type; }
  const Lame& lame() const { return m_lame; }
  SplineEditRegion region() const { return m_region; }
  const CubicSpline& spline() const { return m_spline; }
  /// The base's 1-D term derivative f′(x) and f″(x).
  double f_prime(double x) const;
  double f_second(double x) const;
  /// Δ(x) = ∫₁ˣ (s(t) − 1) f′(t) dt, the energy added per stretch.
  double edit_energy(double x) const;

  private:
  double integrate(double a, double b) const; // ∫ₐᵇ (s − 1) f′, a ≤ b

  ElasticModelType m_base_type;
  Lame m_lame;
  SplineEditRegion m_region;
  CubicSpline m_spline;
  std::unique_ptr<ElasticModel> m_base;
};

} // namespace elastolearn::material
