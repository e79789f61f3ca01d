#pragma once
/// \file General least-squares regression with intercept (paper 004, Eq. 4), optionally with a
/// ridge penalty. Usable for any feature matrix: the phase-space spring (features e, v) and the
/// polynomial / spline features of nonlinear springs share it.
#include <elastolearn/core/types.hpp>

#include <vector>

namespace elastolearn::springs {

/// Options of `fit_linear_regression`.
struct RegressionOptions {
  bool intercept = true; ///< learn β₀ (paper Eq. 4); never penalised by the ridge term
  double ridge = 0.0; ///< λ ≥ 0: minimise ‖y − β₀ − Xβ‖² + λ‖β‖² on standardised columns
  /// Throws InputError("regression options", ...) if ridge is negative or not finite.
  void validate() const;
};

/// A fitted multi-output linear model y ≈ β₀ + Xβ and its fit report.
/// Storage: `coefficients` is (p+1)×q; row 0 is the intercept β₀ (zero if no intercept), row j+1
/// multiplies feature j; column o belongs to output o.
struct LinearRegression {
  MatX coefficients; ///< (p+1)×q, intercept in row 0
  MatX residuals; ///< N×q, y − ŷ on the training data
  std::vector<double>
      r_squared; ///< q values: 1 − SS_res / SS_tot (1 when SS_tot = 0 and the fit is exact)
  std::vector<double> rms_residual; ///< q values: sqrt(SS_res / N)
  int rank = 0; ///< numerical rank of the (augmented) design matrix

  /// Number of features p.
  Eigen::Index features() const { return coefficients.rows() - 1; }
  /// Number of outputs q.
  Eigen::Index outputs() const { return coefficients.cols(); }
  /// Predict for M×p features → M×q outputs.
  MatX predict(ConstRef<MatX> x) const;
};

/// Least-squares fit of Y (N×q) on X (N×p) with rank-revealing Householder QR
/// (Eigen::ColPivHouseholderQR), paper Eq. (4). With ridge > 0 the columns are standardised
/// and the system is augmented with sqrt(λ)·I rows (no penalty on the intercept).
/// Throws InputError("regression data", ...) for mismatched rows, fewer samples than unknowns,
/// non-finite values, or a rank-deficient design without ridge.
LinearRegression fit_linear_regression(
    ConstRef<MatX> x, ConstRef<MatX> y, const RegressionOptions& options = {});

} // namespace elastolearn::springs
