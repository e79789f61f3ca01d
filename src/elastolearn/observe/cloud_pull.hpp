#pragma once
/// \file The pull of a point cloud on the mesh surface (paper 000 §5.3, Eq. 9) as a force term of
/// the simulator: the force of the energy
///   E(x) = (κ/2) Σ_(k,n) w_kn (c_n − s_k(x))ᵀ A_k (c_n − s_k(x)),
///   A_k = τ I + (1 − τ) n_k n_kᵀ,
/// with the correspondence weights w_kn (capture::find_correspondences) and the samples' unit
/// normals n_k held fixed within a Newton solve, s_k the surface samples, κ [N/m] the stiffness
/// of one unit of weight and τ ∈ [0, 1] the weight of the tangential part of a distance. τ = 1 is
/// Eq. (9)'s point-to-point distance; τ < 1 lets the surface slide along the cloud (point-to-plane
/// at τ = 0): a cloud says where the surface is, not where along it a point of the mesh went, and
/// its tangential pull is noise and sampling (depth noise along oblique rays, points on one side
/// of a sample at a scan's edge) that drags the tracked surface sideways. For fixed weights and
/// normals E is quadratic: per sample it needs only W_k = κ Σ_n w_kn and T_k = κ Σ_n w_kn c_n, so
/// evaluating the force is O(samples), not O(pairs):
///   f = −∂E/∂x,  −∂E/∂s_k = A_k (T_k − W_k s_k),
/// and its Jacobian K = −∂f/∂x = Σ_k W_k b_k b_kᵀ ⊗ A_k (b_k the sample's barycentric weights on
/// its three vertices) is constant and positive semi-definite. At τ = 1, κ/σ² ·
/// correspondence_energy is the same E (capture/correspondence.hpp).
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
  /// per unit of weight, the samples' unit normals (K×3, e.g. capture::sample_normals where the
  /// pairs were found; not read, and may be empty, at τ = 1) and the tangential weight
  /// τ ∈ [0, 1]. No pairs: no pull.
  void set_pairs(ConstRef<Positions> cloud, const std::vector<capture::Correspondence>& pairs,
      double stiffness, ConstRef<Positions> normals, double tangential_weight);
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
  std::vector<Mat3> m_metric; ///< A_k per sample
  double m_constant = 0; ///< ½ κ Σ w ‖c‖² [J]
  /// Per sample, for its vertex pair (i, j) and coordinates (d, e): the position in the matrix
  /// values of entry (3 v_i' + d, 3 v_j' + e), or −1 when a vertex is prescribed. 81 per sample.
  std::vector<int> m_slots;
  VecX m_values; ///< the Jacobian in the pattern's values (nnz), rebuilt per evaluation
};

} // namespace elastolearn::observe
