#pragma once
/// \file The nodal forces of a material correction (paper 000 §4.1, Eqs. 1 and 13): the force of
/// a given correction (correction_force), its misfit against target forces, and the linear map
/// from an RBF design's unknowns to that force (CorrectionForceJacobian).
#include <elastolearn/fem/dof_map.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/rbf_fit.hpp>

#include <array>
#include <vector>

namespace elastolearn::learn {

/// Nodal forces [N] (flat 3n) of a correction: what fem::ElasticForce gives with it minus without
/// it, from the correction's part of the one element kernel (material::element_stress): per
/// element f_a = −vol P g_a with
///   P = U diag(N(σ, ḟ)) Vᵀ + [α₁ K^d(N(σ, 0)) + Δα₁ K^d(s_e P̂)] : Ḟ
/// (Eq. 1's N term; the nominal Rayleigh α₁ on the correction's share of the corrected damping
/// stiffness and Eq. 13's Δα₁, kept α₁ + Δα₁ ≥ 0, on the nominal one: ElementStress::
/// damped_by_correction), with α₁, the stiffness scale s_e and the damping tangent K^d of
/// mesh.nominal, and the mass damping a Δα₀ adds on the lumped mass, −Δα₀ (ρ V_e / 4) v_a (kept
/// α₀ + Δα₀ ≥ 0). Without mesh.nominal.elastic only the N and Δα₀ terms. Parallel over elements.
VecX correction_force(const ReconstructionMesh& mesh, const material::Correction& correction,
    const VecX& x, const VecX& v);

/// J of one frame: column i is the nodal force (free dofs) of RBF unknown i alone at a state
/// (x, v), so that the correction's force there (correction_force, restricted) is J x: element e
/// adds [B_e A_e + α₁ D_e [A_e; ∂A_e/∂σ], (−K_e^nom v_e) d_e] (RbfDesign's A, d; Eq. 13) to its
/// free dofs' rows, the same decomposition of the element kernel (material::ElementStress:
/// correction_damping_weight α₁, damped_per_alpha1_change s_e P̂ whose damping force is
/// −K_e^nom v_e; D_e = element_stiffness_damping_operator), exact up to Δα₁'s clamp. The element
/// blocks are computed in parallel in batches and added in element order, so J does not depend
/// on the thread count. With Δα₀ (RbfDesign::mass_damping_unknown) its column is −M v, M the
/// lumped mass (exact up to the clamp α₀ + Δα₀ ≥ 0; a consistent-mass scene damps with its own
/// mass matrix, which this column approximates). Owns its work space (allocated once); one instance
/// per concurrent caller. `mesh`, `dofs` and `design` must outlive it.
class CorrectionForceJacobian {
  public:
  /// Throws InputError if the design fits damping but mesh.nominal has no elastic model.
  CorrectionForceJacobian(
      const ReconstructionMesh& mesh, const fem::DofMap& dofs, const RbfDesign& design);
  /// Jᵀ (unknowns × free dofs) at flat 3n positions x [m] and velocities v [m/s].
  const MatX& transposed(const VecX& x, const VecX& v);
  /// The same, with the elements' principal frames taken from `frames`, a force of the same mesh
  /// whose last add_force was at x (compute_element_states): the SVDs it did already.
  const MatX& transposed(const VecX& x, const VecX& v, const fem::ElasticForce& frames);

  private:
  /// The element blocks of a batch, row-major: each block row is added whole to a column of Jᵀ.
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  /// Element e's 12 × u block into `rows`.
  void element_rows(int e, Eigen::Ref<Rows> rows, RbfDesign::OutputMatrix& outputs,
      RbfDesign::OutputGradient& gradients, Eigen::RowVectorXd& damping_row) const;
  /// Jᵀ at the element states in m_states (velocities v for Δα₀'s column).
  const MatX& assemble_transposed(const VecX& v);

  const ReconstructionMesh& m_mesh;
  const RbfDesign& m_design;
  std::vector<std::array<int, 12>>
      m_free_rows; ///< free index of each element's local dofs (−1: prescribed)
  std::vector<ElementState> m_states;
  /// With Δα₀ in the design: the free dofs (flat indices) and their lumped masses [kg].
  std::vector<int> m_free_dofs;
  VecX m_free_masses;
  MatX m_jt;
  Rows m_batch; ///< 12 rows per element of one batch
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

} // namespace elastolearn::learn
