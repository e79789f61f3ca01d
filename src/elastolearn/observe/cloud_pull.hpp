#pragma once
/// \file The pull of a point cloud on the mesh surface (paper 000 §5.3, Eq. 9) as a force term of
/// the simulator: the force of the energy
///   E(x) = (κ/2) Σ_(k,n) w_kn ‖c_n − s_k(x)‖²,
/// with the correspondence weights w_kn (capture::find_correspondences) held fixed within a
/// Newton solve, s_k the surface samples and κ [N/m] the stiffness of one unit of weight. For
/// fixed weights E is quadratic: per sample it needs only W_k = κ Σ_n w_kn and
/// T_k = κ Σ_n w_kn c_n, so evaluating the force is O(samples), not O(pairs):
///   f = −∂E/∂x,  −∂E/∂s_k = T_k − W_k s_k,
/// and its Jacobian K = −∂f/∂x = Σ_k W_k b_k b_kᵀ ⊗ I₃ (b_k the sample's barycentric weights on
/// its three vertices) is constant and positive semi-definite. κ/σ² · correspondence_energy is
/// the same E (capture/correspondence.hpp).
#include <elastolearn/capture/correspondence.hpp>
#include <elastolearn/capture/surface_samples.hpp>
#include <elastolearn/fem/dof_map.hpp>
#include <elastolearn/fem/force_term.hpp>
#include <elastolearn/fem/system_matrix.hpp>

#include <vector>

namespace elastolearn::observe {

class CloudPull final : public fem::ForceTerm {
  public:
  /// The samples (kept by reference: must outlive the term) of a mesh whose free dofs are
  /// `dofs`, and the system matrix whose pattern the Jacobian is added into (the simulator's; the
  /// three vertices of a surface triangle share a tet, so every entry is in the pattern). Finds
  /// the pattern slots once: O(samples · 27 · log(column length)).
  CloudPull(const capture::SurfaceSamples& samples, const fem::DofMap& dofs,
      const fem::SystemMatrix& pattern);

  /// Hold these pairs (of the samples with the N×3 `cloud`) fixed, with stiffness κ > 0 [N/m]
  /// per unit of weight. No pairs: no pull.
  void set_pairs(ConstRef<Positions> cloud, const std::vector<capture::Correspondence>& pairs,
      double stiffness);
  /// No pull.
  void clear();

  /// E(x) [J] at flat positions x (3n).
  double energy(const VecX& x) const;
  /// f += −∂E/∂x.
  void add_force(const fem::ForceState& state, VecX& f) override;
  /// A += c_x · K over the free dofs (the pull does not depend on v).
  void add_jacobian(
      const fem::ForceState& state, double c_x, double c_v, fem::SystemMatrix& A) override;

  private:
  const capture::SurfaceSamples& m_samples;
  int m_num_vertices = 0;
  std::vector<int> m_active; ///< samples with W_k > 0
  VecX m_weight; ///< W_k [N/m]
  Positions m_target; ///< T_k [N]
  double m_constant = 0; ///< ½ κ Σ w ‖c‖² [J]
  /// Per sample, for its vertex pair (i, j) and coordinate d: the position in the matrix values
  /// of entry (3 v_i' + d, 3 v_j' + d), or −1 when a vertex is prescribed. 27 per sample.
  std::vector<int> m_slots;
  VecX m_values; ///< the Jacobian in the pattern's values (nnz), rebuilt per evaluation
};

} // namespace elastolearn::observe
