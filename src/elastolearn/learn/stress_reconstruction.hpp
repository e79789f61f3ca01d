#pragma once
/// \file Stress reconstruction from nodal forces (paper 000 §6.1, Eqs. 10–13): find the RBF
/// correction N(σ, ḟ) whose nodal forces best explain target forces over all frames of a
/// trajectory. The nodal force of a principal stress p̂ in element e is (§4.1, "B p̂ = f")
///   f_a = −vol · U diag(p̂) Vᵀ g_a,   a = 0..3,
/// with F = U diag(σ) Vᵀ the element's principal frame and g_a the rest shape-function gradients.
/// With p̂ = N(σ, ḟ) in RbfDesign's layout (linear in its unknowns x) this is the linear operator
/// F_t x of frame t. Formulation, damping representation and timings: docs/learning.md,
/// "Stress reconstruction". The LSQR option (Fig. 4) is in stress_reconstruction_lsqr.hpp.
#include <elastolearn/fem/dof_map.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace elastolearn::learn {

/// The per-element rest data the reconstruction needs (precompute once per mesh), and the nominal
/// material whose Rayleigh damping the correction's Δα₁ adds to (Eq. 13). Its `elastic` may be
/// null when no damping is fitted or evaluated (then corrections contribute their N term only).
struct ReconstructionMesh {
  /// From a rest mesh (computes fem::precompute_rest_data).
  explicit ReconstructionMesh(const mesh::TetMesh& mesh, fem::MaterialModel nominal = {});
  /// From rest data already computed (e.g. fem::ElasticForce::rest_data() and tets()).
  /// Throws InputError if `rest` and `tets` differ in length or an index is outside [0, n).
  ReconstructionMesh(std::vector<fem::TetRestData> rest, Tets tets, int num_vertices,
      fem::MaterialModel nominal = {});

  std::vector<fem::TetRestData> rest; ///< m
  Tets tets; ///< m × 4
  int num_vertices = 0; ///< n
  fem::MaterialModel nominal; ///< elastic model and Rayleigh damping (its correction is ignored)

  int num_tets() const { return static_cast<int>(tets.rows()); }
};

/// The state of one element at one frame: principal frame F = U diag(σ) Vᵀ (σ sorted descending)
/// and stretch rates ḟ = diag(Uᵀ Ḟ V) [1/s] (paper §4.2).
struct ElementState {
  material::PrincipalFrame frame;
  Vec3 stretch_rates = Vec3::Zero();
  Mat3 deformation_rate = Mat3::Zero(); ///< Ḟ [1/s]
};

/// Element states of one frame: `x`, `v` flat 3n positions [m] and velocities [m/s]; `states` is
/// resized to m (no allocation once sized). Parallel over elements (oneTBB).
void compute_element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    std::vector<ElementState>& states);

/// The element's principal-stress-to-nodal-force operator (one element's block of the paper's B,
/// §4.1): column k = nodal forces [N per Pa] of a unit principal stress k, i.e. rows 3a + c hold
/// −vol (v_k · g_a) U(c, k). Local dofs ordered x0, y0, z0, x1, ….
Eigen::Matrix<double, 12, 3> element_force_operator(
    const fem::TetRestData& rest, const material::PrincipalFrame& frame);

/// The element's stiffness-damping force per unit Δα₁ [N·s]: −K_e v_e = −vol (dP/dF : Ḟ) g_a
/// with dP/dF the damping tangent of kind `kind` (material::damping_tangent) of the nominal model
/// `elastic`, exactly as fem::ElasticForce applies Δα₁. Local dofs ordered x0, y0, z0, x1, ….
Vec12 element_stiffness_damping_force(const fem::TetRestData& rest, const ElementState& state,
    const material::ElasticModel& elastic, material::DampingTangent kind);

/// The element's stiffness-damping force per unit α₁ as a linear function of a principal stress
/// and its stretch derivative: column c maps entry c of [p̂; vec(∂p̂/∂σ)] (3 + 9, column-major)
/// to the nodal forces −vol (dP/dF : Ḟ) g_a of material::damping_tangent of p̂ (of kind `kind`)
/// [N·s per Pa]. Applied
/// to an RBF unknown's output and gradient (RbfDesign::output_matrix) it gives that unknown's share
/// of the nominal α₁'s action on the corrected stiffness (fem::ElasticForce).
Eigen::Matrix<double, 12, 12> element_stiffness_damping_operator(
    const fem::TetRestData& rest, const ElementState& state, material::DampingTangent kind);

/// Nodal forces [N] (flat 3n) of a correction: what fem::ElasticForce gives with it minus without
/// it, f = Σ_e B_e N(σ_e, ḟ_e) + α₁ (−(K_e − K_e^d) v_e) + [(α₁ + Δα₁)⁺ − α₁] (−K_e^d v_e)
/// with K_e, K_e^d the damping stiffness (material::damping_tangent) of the corrected and the
/// nominal model (Eq. 1's N term, the nominal
/// Rayleigh term on the corrected stiffness, and Eq. 13's damping term; α₁ from
/// mesh.nominal.damping). Without mesh.nominal.elastic only the N term. Parallel over elements.
VecX correction_force(const ReconstructionMesh& mesh, const material::Correction& correction,
    const VecX& x, const VecX& v);

/// J of one frame: column i is the nodal force (free dofs) of RBF unknown i alone at a state
/// (x, v), so that the correction's force there (correction_force, restricted) is J x: element e
/// adds [B_e A_e + α₁ D_e [A_e; ∂A_e/∂σ], (−K_e^nom v_e) d_e] (RbfDesign's A, d; Eq. 13) to its
/// free dofs' rows (exact up to Δα₁'s clamps). The element blocks are computed in parallel in
/// batches and added in element order, so J does not depend on the thread count. Owns its work
/// space (allocated once); one instance per concurrent caller. `mesh`, `dofs` and `design` must
/// outlive it.
class CorrectionForceJacobian {
  public:
  /// Throws InputError if the design fits damping but mesh.nominal has no elastic model.
  CorrectionForceJacobian(
      const ReconstructionMesh& mesh, const fem::DofMap& dofs, const RbfDesign& design);
  /// Jᵀ (unknowns × free dofs) at flat 3n positions x [m] and velocities v [m/s].
  const MatX& transposed(const VecX& x, const VecX& v);

  private:
  /// Element e's 12 × u block into `rows`.
  void element_rows(int e, Eigen::Ref<MatX> rows, RbfDesign::OutputMatrix& outputs,
      RbfDesign::OutputGradient& gradients, Eigen::RowVectorXd& damping_row) const;

  const ReconstructionMesh& m_mesh;
  const RbfDesign& m_design;
  std::vector<std::array<int, 12>>
      m_free_rows; ///< free index of each element's local dofs (−1: prescribed)
  std::vector<ElementState> m_states;
  MatX m_jt;
  MatX m_batch; ///< 12 rows per element of one batch
};

/// Which principal stretches collect_stretches returns.
struct StretchSampleOptions {
  int frame_stride = 1; ///< use frames 0, s, 2s, … (≥ 1)
  /// At most this many rows (≥ 0; 0 = no cap): when there are more (element, frame) samples, every
  /// ⌈N / cap⌉-th is kept, deterministically.
  Eigen::Index max_samples = 0;
  /// Throws InputError("stretch_samples.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The sorted principal stretches of every element at the selected frames, as rows of an N × 3
/// matrix (frame-major, then element), for choosing RBF centres with learn::kmeans (Eq. 10).
/// Throws InputError if a frame is not 3n long, is not finite, or the options are invalid.
MatX collect_stretches(const ReconstructionMesh& mesh, const std::vector<VecX>& positions,
    const StretchSampleOptions& options = {});

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

/// RMS force misfit of a correction against targets over the free dofs.
struct ForceMisfit {
  /// √(Σ_t ‖r_t‖² / (T · n_free)), r_t = restrict_free(f_t − g_t), n_free = free vertices [N]
  double rms_residual = 0;
  double rms_target = 0; ///< the same for g_t alone [N]
  int frames = 0; ///< T, frames used
};

/// Misfit of `correction`'s nodal forces (correction_force) against the targets at frames
/// 0, stride, 2·stride, … Same inputs and checks as reconstruct_rbf_correction.
ForceMisfit correction_force_misfit(const ReconstructionMesh& mesh, const fem::DofMap& dofs,
    const material::Correction& correction, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces,
    int frame_stride = 1);

struct StressReconstructionResult {
  material::RbfCorrection correction; ///< design.correction(unknowns)
  VecX unknowns; ///< x in RbfDesign's layout
  ForceMisfit misfit; ///< of `correction` over the frames used
  int rows_per_frame = 0; ///< free dofs
  // lsqr method only:
  int lsqr_max_iterations = 0; ///< most CGLS iterations of any frame
  double lsqr_max_relative_error = 0; ///< largest ‖Bᵀr‖/‖Bᵀf‖ of any frame at exit
  double stress_rms_residual = 0; ///< RBF fit to the element stresses [Pa]
  // timing [s]:
  double assembly_seconds = 0; ///< element pass + normal equations (or CGLS + samples)
  double solve_seconds = 0; ///< the regularised dense solve (or fit_rbf_correction)
  double misfit_seconds = 0; ///< correction_force_misfit
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
/// nominal model's stiffness (element_stiffness_damping_force); both need `mesh.nominal.elastic`
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

namespace detail {
/// Input checks shared by the reconstruction entry points (throws InputError).
/// `dofs` may be null (no DofMap check), as may `velocities` and `target_forces`.
void check_frames(const ReconstructionMesh& mesh, const fem::DofMap* dofs,
    const std::vector<VecX>& positions, const std::vector<VecX>* velocities,
    const std::vector<VecX>* target_forces);
/// The frame indices 0, stride, 2·stride, … below `count`.
std::vector<int> selected_frames(int count, int stride);
} // namespace detail

} // namespace elastolearn::learn
