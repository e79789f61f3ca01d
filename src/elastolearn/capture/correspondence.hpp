#pragma once
/// \file Probabilistic correspondence between a frame's point cloud and the mesh surface (paper
/// 000 §5.3, Eq. 9, after Schulman et al. 2013). Cloud point c_n is modelled as drawn from an
/// isotropic Gaussian around surface point s_k, so their correspondence weight is the density
///   p_kn = (2π σ²)^(−3/2) exp(−‖c_n − s_k‖² / (2σ²))      [1/m³],
/// with σ the scanner's accuracy, set to zero where exp(…) < `truncation` (only the pairs within
/// σ·√(−2 ln truncation) of each other are kept; a k-d tree over the cloud finds them). The
/// weights are recomputed whenever the mesh moves: call find_correspondences again with the new
/// surface positions; the CloudIndex of the frame is built once.
///
/// The position term of Eq. (9) is the force of the energy
///   E(x) = ½ Σ_(k,n) p_kn ‖c_n − s_k(x)‖² / σ²,
/// with p held fixed (as the paper's Jacobian and the EM view of tracking treat it):
///   −∂E/∂s_k = Σ_n p_kn Σ⁻¹ (c_n − s_k), Eq. (9)'s C up to the weight λ.
/// correspondence_energy returns E and ∂E/∂x for the vertex positions x; the caller multiplies by
/// its own λ.
#include <elastolearn/capture/cloud_index.hpp>
#include <elastolearn/capture/surface_samples.hpp>

#include <Eigen/SparseCore>

#include <vector>

namespace elastolearn::capture {

struct CorrespondenceOptions {
  double sigma = 0; ///< σ [m], the scanner's accuracy (standard deviation of its noise), > 0
  /// Relative threshold in (0, 1): pairs with exp(−d²/2σ²) below it get weight 0. The default
  /// 1e-3 keeps the pairs within 3.72 σ.
  double truncation = 1e-3;
  /// Divide each cloud point's weights by their sum (over the surface samples it pairs with), so
  /// every cloud point pulls with total weight 1 however densely the surface is sampled (the
  /// responsibilities of EM tracking). Off: the paper's p_kn as written.
  bool normalize_per_point = false;

  /// Throws InputError("correspondence.<field>", ...) unless sigma is positive and finite and
  /// truncation is in (0, 1).
  void validate() const;
  /// σ·√(−2 ln truncation): the largest distance of a kept pair [m].
  double radius() const;
};

/// One kept pair: surface sample `sample` (a row of the sample positions) and cloud point `point`
/// (a row of the frame's cloud), with its weight p_kn [1/m³] (or the normalised weight).
struct Correspondence {
  int sample = 0;
  Eigen::Index point = 0;
  double weight = 0;
};

/// The pairs of the surface samples at `sample_positions` (K×3 [m]) and the indexed cloud with a
/// weight above the truncation, sorted by (sample, point): the result depends on the set of cloud
/// points, not on their order (up to renumbering), nor on the number of threads. An empty cloud
/// gives no pairs. Parallel over samples. Throws InputError for invalid options.
std::vector<Correspondence> find_correspondences(const CloudIndex& cloud,
    ConstRef<Positions> sample_positions, const CorrespondenceOptions& options);

/// E(x) = ½ Σ p_kn ‖c_n − s_k(x)‖² / σ² [1/m³] over `pairs` (from find_correspondences with the
/// same samples and cloud), s_k(x) from `samples` at vertex positions x (n×3). If `gradient` is
/// given it is set to ∂E/∂x (n×3, zero rows for vertices no sample uses).
double correspondence_energy(const SurfaceSamples& samples, ConstRef<Positions> x,
    ConstRef<Positions> cloud, const std::vector<Correspondence>& pairs, double sigma,
    Positions* gradient = nullptr);

/// The Hessian of correspondence_energy with respect to x, which for fixed weights is constant:
/// ∂²E/∂x_a∂x_b = H(a, b) · I₃ with H = Σ_k W_k b_k b_kᵀ, W_k = Σ_n p_kn / σ², b_k the sample's
/// barycentric weights spread to its vertices. Returns the scalar n×n matrix H (symmetric,
/// positive semi-definite); the 3n×3n Hessian in the flatten() order is H ⊗ I₃.
Eigen::SparseMatrix<double> correspondence_hessian(const SurfaceSamples& samples, int num_vertices,
    const std::vector<Correspondence>& pairs, double sigma);

} // namespace elastolearn::capture
