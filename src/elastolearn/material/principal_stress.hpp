#pragma once
/// \file From principal stretches to the world frame: inversion-safe SVD, the first Piola stress
/// P = U P̂ Vᵀ and its derivative dP/dF, for any diagonal stress function (hyperelastic model,
/// corrected model). 9×9 derivatives use column-major vec on both sides (see core/types.hpp).
#include <elastolearn/core/types.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/damping_model.hpp>
#include <elastolearn/material/elastic_model.hpp>

namespace elastolearn::material {

/// F = U diag(stretches) Vᵀ with U, V proper rotations (det = +1) and stretches sorted
/// descending. If F is inverted (det F < 0) the smallest stretch is negative (Irving et al. 2004).
struct PrincipalFrame {
  Mat3 U;
  Vec3 stretches;
  Mat3 V;
};

/// Inversion-safe SVD of F (see PrincipalFrame).
PrincipalFrame principal_frame(const Mat3& F);

/// Stretch rates Ḟ̂ = diag(Uᵀ Ḟ V) (paper 000 §4.2).
Vec3 stretch_rates(const PrincipalFrame& frame, const Mat3& F_rate);

/// P = U diag(principal_stress) Vᵀ.
Mat3 first_piola(const PrincipalFrame& frame, const Vec3& principal_stress);

/// dP/dF of P = U P̂(σ(F)) Vᵀ in its eigen-form (see first_piola_derivative): the 3×3 block
/// ∂P̂/∂σ and, per stretch pair (0,1), (0,2), (1,2), the twist and flip eigenvalues
/// (P̂ᵢ − P̂ⱼ)/(σᵢ − σⱼ) and (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ) (stable limits near equal or opposite
/// stretches). With `project_psd` the block is made symmetric PSD and the eigenvalues ≥ 0.
struct PrincipalTangent {
  Mat3 block;
  Vec3 twist;
  Vec3 flip;
};
PrincipalTangent principal_tangent(const PrincipalFrame& frame, const Vec3& principal_stress,
    const Mat3& principal_stress_derivative, bool project_psd);
/// The same for an uncorrected model at the frame's stretches.
PrincipalTangent principal_tangent(
    const ElasticModel& model, const PrincipalFrame& frame, bool project_psd);
/// The tangent with its block made symmetric PSD and its twist and flip eigenvalues ≥ 0 (what
/// `project_psd` does, for a tangent formed otherwise, e.g. as a weighted sum).
PrincipalTangent projected(const PrincipalTangent& tangent);
/// Symmetric part of a 3×3 matrix with its negative eigenvalues clamped to zero.
Mat3 symmetric_psd(const Mat3& a);
/// The stiffness that Rayleigh damping scales (fem::ElasticForce): the exact tangent of P̂,
/// unprojected, with its flip eigenvalues set to zero for DampingTangent::FlipFree (see
/// damping_model.hpp). Linear in (P̂, ∂P̂/∂σ) either way.
PrincipalTangent damping_tangent(const PrincipalFrame& frame, const Vec3& principal_stress,
    const Mat3& principal_stress_derivative, DampingTangent kind);
/// The same for an uncorrected model at the frame's stretches.
PrincipalTangent damping_tangent(
    const ElasticModel& model, const PrincipalFrame& frame, DampingTangent kind);
/// The 9×9 dP/dF of an eigen-form tangent (symmetric if the tangent was projected).
Mat9 first_piola_derivative(const PrincipalFrame& frame, const PrincipalTangent& tangent);
/// dP = (dP/dF) : dF without forming the 9×9: dP = U dP̂ Vᵀ with, for dF̂ = Uᵀ dF V,
/// dP̂ᵢᵢ = Σⱼ block(i,j) dF̂ⱼⱼ and per pair dP̂ᵢⱼ = ½(twist s + flip d), dP̂ⱼᵢ = ½(twist s − flip d),
/// s = dF̂ᵢⱼ + dF̂ⱼᵢ, d = dF̂ᵢⱼ − dF̂ⱼᵢ. About a tenth of the work of forming dP/dF.
Mat3 first_piola_differential(
    const PrincipalFrame& frame, const PrincipalTangent& tangent, const Mat3& dF);

/// dP/dF (9×9) of P = U P̂(σ(F)) Vᵀ for an isotropic diagonal stress P̂(σ) with 3×3 derivative
/// ∂P̂/∂σ. With `project_psd` the 3×3 block and the three 2×2 twist/flip blocks are made symmetric
/// and their negative eigenvalues clamped to zero (Xu et al. 2015; Teran et al. 2005), so the
/// result is symmetric positive semi-definite. Without it the exact derivative is returned
/// (including near-equal stretches, handled by a stable limit).
Mat9 first_piola_derivative(const PrincipalFrame& frame, const Vec3& principal_stress,
    const Mat3& principal_stress_derivative, bool project_psd);

/// ∂P/∂Ḟ (9×9) of P = U N(σ, Ḟ̂) Vᵀ with respect to Ḟ, for ∂N/∂Ḟ̂ = `d_stretch_rates`
/// (U and V depend on F only, so this is exact).
Mat9 first_piola_rate_derivative(const PrincipalFrame& frame, const Mat3& d_stretch_rates);

/// Elastic model plus optional correction, evaluated at one element state.
struct CorrectedStress {
  Vec3 stress; ///< P̂(σ) + N(σ, Ḟ̂)
  Mat3 d_stretches; ///< ∂(P̂ + N)/∂σ with Ḟ̂ held fixed
  Mat3 d_stretch_rates; ///< ∂N/∂Ḟ̂ (zero without a correction)
};

/// Evaluate P̂ + N at (σ, Ḟ̂). `correction` may be null. (An element's stress with its stiffness
/// scale and damping: material::element_stress.)
CorrectedStress corrected_principal_stress(const ElasticModel& model, const Correction* correction,
    const Vec3& stretches, const Vec3& stretch_rates);

/// Convenience for tests and tools: P(F) of a model (no correction).
Mat3 first_piola(const ElasticModel& model, const Mat3& F);
/// Convenience: dP/dF of a model at F.
Mat9 first_piola_derivative(const ElasticModel& model, const Mat3& F, bool project_psd);
/// Convenience: Ψ(F) of a model.
double energy(const ElasticModel& model, const Mat3& F);

} // namespace elastolearn::material
