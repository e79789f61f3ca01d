#pragma once
/// \file The stress of one element (paper 000 Eq. 1) and its stiffness damping (Eqs. 2 and 13),
/// stated once and split into the nominal and the correction parts: fem::ElasticForce applies the
/// whole, learn::correction_force the correction's part, and learn::CorrectionForceJacobian the
/// correction's part as a linear map of an RBF design's unknowns. Rationale: docs/learning.md,
/// "Damping part".
#include <elastolearn/core/types.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/damping_model.hpp>
#include <elastolearn/material/elastic_model.hpp>
#include <elastolearn/material/principal_stress.hpp>

namespace elastolearn::material {

/// A principal stress p̂ [Pa] and its stretch derivative ∂p̂/∂σ [Pa] (row = stress component),
/// what a damping tangent is made of (damping_tangent is linear in the pair).
struct StressPair {
  Vec3 stress = Vec3::Zero();
  Mat3 d_stretches = Mat3::Zero();
};

/// The material of one element, as the kernel reads it (non-owning).
struct ElementMaterial {
  /// The nominal model P̂(σ). Null: no nominal stress (a correction's N alone; then a Δα₁ has no
  /// stiffness to scale and is 0).
  const ElasticModel* elastic = nullptr;
  const Correction* correction = nullptr; ///< optional N(σ, ḟ) and Δα₁(σ)
  const DampingModel* damping = nullptr; ///< optional Rayleigh (α₀, α₁)(σ₀)
  double stiffness_scale = 1; ///< s_e > 0: the element's nominal stress is s_e P̂ (not N)
};

/// One element's principal-frame stresses in parts, at stretches σ (sorted descending) and stretch
/// rates ḟ. The element's first Piola stress is
///   P = U diag(corrected().stress) Vᵀ + T(damped()) : Ḟ,   T = damping_tangent (the damping
/// model's kind, unprojected), i.e. paper Eq. 1 plus the stiffness damping −(α₁ K_e^d + Δα₁
/// K_e^nom,d) v_e of fem::ElasticForce:
/// - the nominal Rayleigh α₁ damps the tangent of the *corrected* elastic stress s P̂ + N(σ, 0)
///   (a correction that learns the truth's elasticity also reproduces its Rayleigh damping);
/// - a learned Δα₁ (Correction::stiffness_damping, kept α₁ + Δα₁ ≥ 0) damps the tangent of the
///   *nominal* s P̂, so the damping stays linear in the correction's unknowns.
/// Since T is linear in its pair, damped() is one pair, and what the correction adds to P (with
/// the correction minus without it) is U diag(N) Vᵀ + T(damped_by_correction()) : Ḟ.
struct ElementStress {
  StressPair nominal; ///< s P̂(σ), s ∂P̂/∂σ (zero without an elastic model)
  bool has_correction = false; ///< whether the material has a correction (else N ≡ 0, Δα₁ = 0)
  // The correction's fields are valid only if has_correction (left unset otherwise: the
  // simulator's element loop without a correction should not write them).
  Vec3 correction {}; ///< N(σ, ḟ) [Pa]
  Mat3 correction_d_stretches {}; ///< ∂N/∂σ at (σ, ḟ)
  Mat3 correction_d_rates {}; ///< ∂N/∂ḟ at (σ, ḟ) [Pa·s]
  /// N(σ, 0) and ∂N/∂σ there: the correction's share of the stiffness α₁ damps (the damping
  /// tangent of a rate-dependent N would blow up where σᵢ ≈ σⱼ but ḟᵢ ≠ ḟⱼ). Zero if nothing
  /// damps it (has_damping() false).
  StressPair correction_elastic { Vec3 {}, Mat3 {} };
  RayleighCoefficients alpha; ///< the damping model's α₀ [1/s], α₁ [s] at σ₀ (0 without one)
  /// The mass-damping coefficient applied: (α₀ + Δα₀)⁺ with the correction's Δα₀
  /// (corrected_mass_damping), α₀ without one [1/s].
  double mass_damping = 0;
  double alpha1_change = 0; ///< Δα₁ as applied: (α₁ + Δα₁)⁺ − α₁ ≥ −α₁ [s]

  /// s P̂ + N, ∂(s P̂ + N)/∂σ and ∂N/∂ḟ: the corrected stress of Eq. 1.
  CorrectedStress corrected() const {
    if (!has_correction)
      return { nominal.stress, nominal.d_stretches, Mat3::Zero() };
    return { nominal.stress + correction, nominal.d_stretches + correction_d_stretches,
      correction_d_rates };
  }
  /// Whether there is any stiffness damping (α₁ ≠ 0 or Δα₁ ≠ 0).
  bool has_damping() const { return alpha.alpha1 != 0 || alpha1_change != 0; }
  /// The weight of N(σ, 0) in damped(): α₁ (the nominal α₁ damps the corrected stiffness).
  double correction_damping_weight() const { return alpha.alpha1; }
  /// The pair a unit Δα₁ adds to damped(): s P̂ (a learned Δα₁ damps the nominal stiffness).
  const StressPair& damped_per_alpha1_change() const { return nominal; }
  /// α₁ N(σ, 0) + Δα₁ s P̂: damped() with the correction minus damped() without it.
  StressPair damped_by_correction() const {
    if (!has_correction)
      return {};
    const double weight = correction_damping_weight();
    const StressPair& per_change = damped_per_alpha1_change();
    return { weight * correction_elastic.stress + alpha1_change * per_change.stress,
      weight * correction_elastic.d_stretches + alpha1_change * per_change.d_stretches };
  }
  /// α₁ s P̂ + damped_by_correction(): the pair whose damping tangent is the element's
  /// stiffness-damping tangent α₁ K_e^d + Δα₁ K_e^nom,d.
  StressPair damped() const {
    if (!has_correction) // N = 0, Δα₁ = 0
      return { alpha.alpha1 * nominal.stress, alpha.alpha1 * nominal.d_stretches };
    StressPair d = damped_by_correction();
    d.stress += alpha.alpha1 * nominal.stress;
    d.d_stretches += alpha.alpha1 * nominal.d_stretches;
    return d;
  }
};

/// The kernel: the element's stresses at stretches σ (sorted descending) and stretch rates ḟ
/// (used only by a rate-dependent correction). No allocation if the models allocate none.
ElementStress element_stress(
    const ElementMaterial& material, const Vec3& stretches, const Vec3& stretch_rates);

/// damping_tangent of a pair (the stiffness the damping model's `kind` names, unprojected).
inline PrincipalTangent damping_tangent(
    const PrincipalFrame& frame, const StressPair& pair, DampingTangent kind) {
  return damping_tangent(frame, pair.stress, pair.d_stretches, kind);
}

/// P = U diag(p̂) Vᵀ + (T : Ḟ) [Pa]: the first Piola stress of a principal stress p̂ plus, if
/// `damping` is not null, the stiffness-damping stress of the eigen-form tangent T = *damping
/// (damping_tangent of ElementStress::damped or damped_by_correction) at the strain rate Ḟ [1/s].
inline Mat3 element_first_piola(const PrincipalFrame& frame, const Vec3& principal_stress,
    const PrincipalTangent* damping, const Mat3& F_rate) {
  Mat3 P = first_piola(frame, principal_stress);
  if (damping != nullptr)
    P += first_piola_differential(frame, *damping, F_rate);
  return P;
}

} // namespace elastolearn::material
