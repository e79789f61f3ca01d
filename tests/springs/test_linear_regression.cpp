#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/linear_regression.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace elastolearn;
using namespace elastolearn::springs;

namespace {
MatX random_matrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      m(i, j) = u(rng);
  return m;
}
} // namespace

TEST(LinearRegression, RecoversExactCoefficientsWithIntercept) {
  const MatX x = random_matrix(50, 3, 1);
  MatX beta(4, 2);
  beta << 0.5, -2.0, 1.0, 3.0, -4.0, 0.25, 2.0, -1.0;
  MatX y = x * beta.bottomRows(3);
  y.rowwise() += beta.row(0);
  const LinearRegression fit = fit_linear_regression(x, y);
  // Noise-free data: the least-squares solution is exact up to round-off (~1e-15 · cond).
  EXPECT_LT((fit.coefficients - beta).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT(fit.residuals.cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_NEAR(fit.r_squared[0], 1.0, 1e-14);
  EXPECT_EQ(fit.rank, 3);
  EXPECT_LT((fit.predict(x) - y).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(LinearRegression, NoisyFitReportsResidualsAndRSquared) {
  const MatX x = random_matrix(2000, 1, 2);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  MatX y(2000, 1);
  for (int i = 0; i < 2000; ++i)
    y(i, 0) = 1.0 + 2.0 * x(i, 0) + noise(rng);
  const LinearRegression fit = fit_linear_regression(x, y);
  // 2000 samples with σ = 0.1: slope standard error ≈ 0.1/sqrt(2000·1/3) ≈ 0.004.
  EXPECT_NEAR(fit.coefficients(1, 0), 2.0, 0.02);
  EXPECT_NEAR(fit.coefficients(0, 0), 1.0, 0.02);
  EXPECT_NEAR(fit.rms_residual[0], 0.1, 0.01);
  EXPECT_GT(fit.r_squared[0], 0.9);
  EXPECT_LT(fit.r_squared[0], 1.0);
  // Residuals of a least-squares fit with intercept have zero mean and are orthogonal to X.
  EXPECT_NEAR(fit.residuals.mean(), 0.0, 1e-12);
  EXPECT_NEAR((fit.residuals.transpose() * x)(0, 0), 0.0, 1e-10);
}

TEST(LinearRegression, RidgeShrinksTowardsZeroButNotTheIntercept) {
  const MatX x = random_matrix(100, 2, 4);
  MatX y = 5.0 + (x * Eigen::Vector2d(1.0, -1.0)).array();
  const LinearRegression plain = fit_linear_regression(x, y);
  const LinearRegression ridge = fit_linear_regression(x, y, { true, 100.0 });
  EXPECT_LT(ridge.coefficients.bottomRows(2).norm(), plain.coefficients.bottomRows(2).norm());
  EXPECT_NEAR(ridge.coefficients(0, 0), 5.0, 0.2); // intercept not penalised (x has ~zero mean)
}

TEST(LinearRegression, RejectsBadData) {
  const MatX x = random_matrix(10, 2, 5);
  EXPECT_THROW(fit_linear_regression(x, MatX::Zero(9, 1)), InputError);
  MatX collinear(10, 2);
  collinear.col(0) = x.col(0);
  collinear.col(1) = 2.0 * x.col(0);
  EXPECT_THROW(fit_linear_regression(collinear, MatX::Zero(10, 1)), InputError);
  MatX with_nan = x;
  with_nan(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(fit_linear_regression(with_nan, MatX::Zero(10, 1)), InputError);
  EXPECT_THROW(fit_linear_regression(x, MatX::Zero(10, 1), { true, -1.0 }), InputError);
}
