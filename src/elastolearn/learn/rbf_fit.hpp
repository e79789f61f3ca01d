#pragma once
/// \file Least-squares fit of an RbfCorrection (paper 000 §6.1, Eqs. 10–13) to samples of
/// (principal stretches, stretch rates) → principal stress correction, with Tikhonov
/// regularisation. RbfDesign fixes the unknowns' layout so that the stress reconstruction of the
/// learning loop (Eq. 13, through the nodal-force operator B) can reuse features and unpacking.
#include <elastolearn/material/rbf_correction.hpp>

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
  /// Throws InputError("rbf_fit.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The unknowns of an RBF correction with given centres, and its features.
/// Features b(σ) = (φ_1 … φ_m, σ₁−1, σ₂−1, σ₃−1, 1) of sorted stretches σ (the last 4 exist only
/// with a polynomial tail). Unknowns x = [W(:,0); W(:,1); W(:,2); V], where column k of W holds
/// the elastic weights of output k over the q_e elastic features, and V the q_d damping weights:
///   N_k(σ, ḟ) = W(:,k)ᵀ b_e(σ) + (Vᵀ b_d(σ)) (D ḟ)_k,
/// b_e, b_d being the first q_e, q_d features (m, or m + 4 with the tail).
class RbfDesign {
  public:
  /// `centres` m × 3 (m ≥ 1, finite). Throws InputError for invalid options or centres.
  RbfDesign(ConstRef<MatX> centres, const RbfFitOptions& options);

  int num_centres() const { return static_cast<int>(m_centres.rows()); }
  /// Length of b(σ): m + 4 (the tail slots are always computed).
  int num_features() const { return num_centres() + 4; }
  int elastic_features() const { return m_elastic; } ///< q_e
  int damping_features() const { return m_damping; } ///< q_d (0 without damping)
  int num_unknowns() const { return 3 * m_elastic + m_damping; }
  const RbfFitOptions& options() const { return m_options; }

  /// b(σ) into `out` (length num_features()) for stretches σ sorted descending. No allocation.
  void features(const Vec3& sorted_stretches, Eigen::Ref<VecX> out) const;
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
/// unknowns of `design`. Each sample is put in descending stretch order (its rates and targets
/// permuted alike), as RbfCorrection evaluates. The normal equations are accumulated in chunks
/// from five products Bᵀ diag(·) B of the feature matrix, so the cost is O(N q²) and memory
/// O(q² + chunk·q), q = m + 4; solved by dense Cholesky.
/// Throws InputError if the sample arrays disagree in size, are empty or not finite, or the
/// regularised normal matrix is singular (e.g. λ = 0 with fewer independent samples than
/// unknowns, or damping fitted from zero stretch rates).
RbfFitResult fit_rbf_correction(const RbfDesign& design, const StressSamples& samples);

} // namespace elastolearn::learn
