#pragma once
/// \file Stress reconstruction from nodal forces (paper 000 §6.1, Eqs. 10–13): find the RBF
/// correction N(σ, ḟ) whose nodal forces best explain target forces over all frames of a
/// trajectory. The nodal force of a principal stress p̂ in element e is (§4.1, "B p̂ = f")
///   f_a = −vol · U diag(p̂) Vᵀ g_a,   a = 0..3,
/// with F = U diag(σ) Vᵀ the element's principal frame and g_a the rest shape-function gradients.
/// With p̂ = N(σ, ḟ) in RbfDesign's layout (linear in its unknowns x) this is the linear operator
/// F_t x of frame t. Formulation, damping representation and timings: docs/learning.md,
/// "Stress reconstruction". The LSQR option (Fig. 4) is in stress_reconstruction_lsqr.hpp.
#include <elastolearn/learn/correction_force.hpp>
#include <elastolearn/learn/rbf_fit.hpp>

#include <span>
#include <string>
#include <vector>

namespace elastolearn::learn {

/// How the RBF unknowns are found.
enum class ReconstructionMethod {
  normal_equations, ///< Eq. 13 directly: least squares through the nodal-force operator
  lsqr, ///< per frame min-norm element stresses (CGLS), then fit_rbf_correction (Fig. 4)
};
/// "normal_equations" / "lsqr".
std::string reconstruction_method_name(ReconstructionMethod method);
/// Inverse of reconstruction_method_name; throws InputError(where, ...) for an unknown name.
ReconstructionMethod reconstruction_method_from_name(
    const std::string& name, const std::string& where = "stress_reconstruction.method");

struct StressReconstructionOptions {
  ReconstructionMethod method = ReconstructionMethod::normal_equations;
  int frame_stride = 1; ///< use frames 0, s, 2s, … (≥ 1)
  /// CGLS (lsqr method): stop when ‖Bᵀ(f − B p̂)‖ ≤ tolerance · ‖Bᵀ f‖ (> 0) …
  double lsqr_tolerance = 1e-8;
  /// … or after this many iterations (≥ 0; 0 = 2 × the number of element stresses).
  int lsqr_max_iterations = 0;
  /// With a force projection P (reconstruct_rbf_correction's `projection`): the weight μ ≥ 0 of
  /// the unprojected misfit next to the projected one. μ = 0 leaves the correction's forces
  /// outside span P unconstrained, and a learned correction can then blow up on motions larger
  /// than the training. 0.1 is the weight that keeps every learning-benchmark target the
  /// unprojected fit meets (the comparison of weights: docs/learning.md, "Projected
  /// reconstruction").
  double full_space_weight = 0.1;
  /// Throws InputError("stress_reconstruction.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// Where a reconstructed correction must be stable: nominal + correction at every row of
/// `samples` (principal stretches), held there by stability cuts (stability_cuts.hpp).
struct StabilityRequirement {
  const material::ElasticModel& nominal;
  Eigen::Ref<const MatX> samples;
};

struct StressReconstructionResult {
  material::RbfCorrection correction; ///< design.correction(unknowns)
  VecX unknowns; ///< x in RbfDesign's layout
  ForceMisfit misfit; ///< of `correction` over the frames used
  Eigen::Index stability_cuts = 0; ///< conditions the fit was held to (StabilityRequirement)
  int rows_per_frame = 0; ///< free dofs (summed over the motions)
  // lsqr method only:
  int lsqr_max_iterations = 0; ///< most CGLS iterations of any frame
  double lsqr_max_relative_error = 0; ///< largest ‖Bᵀr‖/‖Bᵀf‖ of any frame at exit
  double stress_rms_residual = 0; ///< RBF fit to the element stresses [Pa]
  // timing [s]:
  double assembly_seconds = 0; ///< element pass + normal equations (or CGLS + samples)
  double solve_seconds = 0; ///< the regularised dense solve (or fit_rbf_correction)
  double misfit_seconds = 0; ///< correction_force_misfit
};

/// One motion's part of a joint reconstruction, viewed (not owned): the arguments of the
/// single-motion reconstruct_rbf_correction below. Motions may have different meshes.
struct ReconstructionMotion {
  const ReconstructionMesh& mesh;
  const fem::DofMap& dofs; ///< 3n dofs of `mesh`
  const std::vector<VecX>& positions; ///< flat 3n per frame [m]
  const std::vector<VecX>& velocities; ///< flat 3n per frame [m/s]
  const std::vector<VecX>& target_forces; ///< flat 3n per frame [N]
  Eigen::Ref<const MatX> projection; ///< free dofs × r, orthonormal columns; empty = none
};

/// Find the unknowns x of `design` minimising (paper Eqs. 12–13)
///   Σ_t ‖restrict_free(F_t x) − restrict_free(g_t)‖²  + Tikhonov,
/// or, with a force projection P (`projection`: free dofs × r, orthonormal columns, e.g. the
/// space-time optimisation's POD basis on the free dofs; empty = none),
///   Σ_t ‖Pᵀ r_t‖² + μ Σ_t ‖r_t‖²  + Tikhonov,   r_t = restrict_free(F_t x − g_t),
/// with μ = options.full_space_weight: the misfit is measured mainly where the reduced
/// space-time optimisation controls the residual (docs/learning.md, "Projected reconstruction"),
/// F_t x = Σ_e (G_e A_e + α₁ D_e [A_e; ∂A_e/∂σ]) x_e + (−K_e v_e) d_e x_d the nodal force of the
/// correction with unknowns x at frame t (= correction_force while α₁ + Δα₁ ≥ 0), and g_t
/// (target_forces[t], flat 3n, only free dofs used) the force the new correction must produce
/// (current correction force + control force). D_e is element_stiffness_damping_operator, K_e the
/// nominal model's damping stiffness (of material::ElementStress::damped_per_alpha1_change, the
/// kernel fem::ElasticForce applies; see CorrectionForceJacobian); both need `mesh.nominal.elastic`
/// (required when the design fits damping; without it the α₁ term is left out). Tikhonov:
/// design.options().regularization on the Jacobi-scaled unknowns, as fit_rbf_correction.
/// Method normal_equations: J_t (free dofs × q) is assembled per frame and JᵀJ accumulated by
/// symmetric rank updates, in parallel over fixed blocks of frames summed in order
/// (deterministic for any thread count); then dense Cholesky. Method lsqr:
/// reconstruct_rbf_correction_via_lsqr.
/// Throws InputError if the frame lists differ in length or are empty, a vector is not 3n long
/// or not finite, the DofMap has not 3n dofs or no free dof, the options are invalid, the
/// projection has not one row per free dof (or is combined with the lsqr method), or the
/// regularised normal matrix is singular. The reported misfit is always the unprojected one.
StressReconstructionResult reconstruct_rbf_correction(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const RbfDesign& design, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces,
    const StressReconstructionOptions& options = {}, ConstRef<MatX> projection = MatX());

/// The same fit over several motions' frames at once (a training set): the sum over motions of
/// each motion's misfit (with its own projection and μ-weighted rest), one Tikhonov term, so
/// that one correction explains every motion. The equations of each motion are accumulated as
/// above (its own blocks of frames) and the motions' sums added in order, so that one motion
/// gives exactly the single-motion result. `misfit` is over all motions' frames together.
/// options.frame_stride applies to every motion. The lsqr method fits one RBF to every motion's
/// element-stress samples. With `stability` (normal_equations only), the least squares are
/// solved subject to the stability cuts that hold the correction stable at its samples
/// (stable_least_squares); the result may still be unstable where the cuts did not converge.
/// Throws InputError as above, and for no motion.
StressReconstructionResult reconstruct_rbf_correction(std::span<const ReconstructionMotion> motions,
    const RbfDesign& design, const StressReconstructionOptions& options = {},
    const StabilityRequirement* stability = nullptr);

/// The misfit of `correction` over every motion's frames 0, stride, 2·stride, …: the RMS over
/// all of them (each motion's correction_force_misfit weighted by its frames × free vertices;
/// one motion's is returned as it is). Same checks as correction_force_misfit.
ForceMisfit correction_force_misfit(std::span<const ReconstructionMotion> motions,
    const material::Correction& correction, int frame_stride = 1);

} // namespace elastolearn::learn
