#pragma once
/// \file Least-squares fit of an RbfCorrection (paper 000 §6.1, Eqs. 10–13) to samples of
/// (principal stretches, stretch rates) → principal stress correction, with Tikhonov
/// regularisation. RbfDesign fixes the unknowns' layout so that the stress reconstruction of the
/// learning loop (Eq. 13, through the nodal-force operator B) can reuse the same map from unknowns to stresses.
#include <elastolearn/material/rbf_correction.hpp>

#include <limits>

namespace elastolearn::learn {

struct RbfFitOptions {
  double epsilon = 1e-3; ///< kernel smoothing ε of material::rbf_kernel [-]
  bool elastic_polynomial = true; ///< fit the linear tail A(σ − 1) + b of the elastic part
  bool fit_damping = true; ///< fit the damping RBF Δα₁(σ) (needs stretch rates and D)
  bool damping_polynomial = true; ///< fit the linear tail aᵀ(σ − 1) + a₀ of Δα₁
  /// Principal damping tangent D [Pa] (see material::RbfCorrection), used when fit_damping.
  Mat3 damping_tangent = Mat3::Zero();
  /// Tikhonov weight λ ≥ 0 on the Jacobi-scaled unknowns: (S⁻¹JᵀJS⁻¹ + λI) S x = S⁻¹Jᵀy with
  /// S = √diag(JᵀJ), so λ is dimensionless and independent of the units of each unknown.
  double regularization = 1e-9;
  /// The same for the damping unknowns. Stretch rates are small and the damping force is a
  /// small part of the force, so its unknowns are poorly determined by data: a stronger
  /// prior keeps Δα₁ from over-fitting noise (which makes simulations unstable).
  double damping_regularization = 1e-3;
  /// Floor of Δα₁ written into the correction (material::RbfCorrection::damping_floor) [s].
  double damping_floor = -std::numeric_limits<double>::infinity();
  /// Throws InputError("rbf_fit.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The unknowns of an RBF correction with given centres, and the linear map from them to N.
/// Unknowns x = [w (m); a, b, c (with the elastic tail); v (m); a_d, a₀ (with the damping tail)]
/// (the damping part only when fitted), in the notation of material::RbfCorrection:
///   N(σ, ḟ) = A(σ, ḟ) x,  row k of A = [φ_i(y_k) …, y_k1 − 1, y_k2 + y_k3 − 2, 1,
///                                       (D ḟ)_k · (φ_i(sort↓ σ) …, Σσ − 3, 1)].
class RbfDesign {
public:
  using OutputMatrix = Eigen::Matrix<double, 3, Eigen::Dynamic>;
  /// `centres` m × 3 (m ≥ 1, finite). Throws InputError for invalid options or centres.
  RbfDesign(ConstRef<MatX> centres, const RbfFitOptions& options);
  int num_centres() const { return static_cast<int>(m_centres.rows()); }
  int elastic_unknowns() const { return m_elastic; } ///< m (+ 3 with the tail)
  int damping_unknowns() const { return m_damping; } ///< 0, or m (+ 2 with the tail)
  int num_unknowns() const { return m_elastic + m_damping; }
  const RbfFitOptions& options() const { return m_options; }
  /// A(σ, ḟ) into `out` (3 × num_unknowns()), for stretches in any order. No allocation.
  void output_matrix(const Vec3& stretches, const Vec3& stretch_rates, Eigen::Ref<OutputMatrix> out) const;
  /// Tikhonov weight of each unknown (regularization, or damping_regularization).
  VecX regularization_weights() const;
  /// The correction whose unknowns are `x` (length num_unknowns()).
  material::RbfCorrection correction(ConstRef<VecX> x) const;

private:
  material::RbfCorrection::Centres m_centres;
  RbfFitOptions m_options;
  int m_elastic = 0;
  int m_damping = 0;
};

/// Stress samples: row j is one element at one frame.
struct StressSamples {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> stretches; ///< N × 3 [-]
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> stretch_rates; ///< N × 3 [1/s]
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> targets; ///< N × 3 [Pa]
};

struct RbfFitResult {
  material::RbfCorrection correction;
  VecX unknowns; ///< x in RbfDesign's layout
  double rms_residual = 0; ///< √(mean ‖N(σ_j, ḟ_j) − y_j‖²) over the samples [Pa]
  double rms_target = 0; ///< √(mean ‖y_j‖²) [Pa]
  int samples = 0;
};

/// Minimise Σ_j ‖N(σ_j, ḟ_j) − y_j‖² + Tikhonov (see RbfFitOptions::regularization) over the
/// unknowns of `design`. The normal equations are accumulated in chunks by symmetric rank
/// updates of the stacked output matrices, O(N u²) time and O(u² + chunk·u) memory for
/// u = num_unknowns(); solved by dense Cholesky.
/// Throws InputError if the sample arrays disagree in size, are empty or not finite, or the
/// regularised normal matrix is singular (e.g. λ = 0 with fewer independent samples than
/// unknowns, or damping fitted from zero stretch rates).
RbfFitResult fit_rbf_correction(const RbfDesign& design, const StressSamples& samples);

/// The stretch views (material::stretch_view) of every sample, 3N × 3 (rows 3j..3j+2 are sample
/// j's three directions): the points the RBF centres should cover, e.g. by k-means.
MatX stretch_views(ConstRef<MatX> stretches);

/// Solve the normal equations `normal` x = `rhs` (symmetric, full) with Jacobi scaling
/// S = √diag and Tikhonov λ_i (one per unknown) on the scaled unknowns:
/// (S⁻¹ N S⁻¹ + diag λ) S x = S⁻¹ rhs.
/// `samples` is only quoted in the error. Throws InputError if the system is singular.
VecX solve_regularised_normal_equations(MatX normal, ConstRef<VecX> rhs, ConstRef<VecX> regularization, long samples);

} // namespace elastolearn::learn
