#pragma once
/// \file One generic finite-difference checker for every energy, force, correction and residual
/// in the test suite (as PolyFEM's test_form / IPC's FD checks).
///
/// `fd_jacobian(f, x)` approximates ∂f/∂x with 4th-order central differences (error O(h⁴)).
/// `expect_jacobian_matches(...)` compares an analytic Jacobian with it, relative to the
/// Jacobian's magnitude, and reports the worst entry.
#include <Eigen/Core>
#include <functional>
#include <gtest/gtest.h>

namespace elastolearn::test {

using FdFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

/// 4th-order central-difference Jacobian of f at x, step h (relative to max(1, |x_j|)).
inline Eigen::MatrixXd fd_jacobian(const FdFunction& f, const Eigen::VectorXd& x, double h = 1e-4) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  Eigen::VectorXd xp = x;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double step = h * std::max(1.0, std::abs(x[j]));
    auto eval = [&](double delta) {
      xp[j] = x[j] + delta;
      Eigen::VectorXd r = f(xp);
      xp[j] = x[j];
      return r;
    };
    J.col(j) = (-eval(2 * step) + 8 * eval(step) - 8 * eval(-step) + eval(-2 * step)) / (12 * step);
  }
  return J;
}

/// Gradient of a scalar function, as a column vector.
inline Eigen::VectorXd fd_gradient(const std::function<double(const Eigen::VectorXd&)>& f,
    const Eigen::VectorXd& x, double h = 1e-4) {
  FdFunction wrapped = [&](const Eigen::VectorXd& y) { return Eigen::VectorXd::Constant(1, f(y)); };
  return fd_jacobian(wrapped, x, h).transpose();
}

/// Assert that `analytic` matches the FD Jacobian of f at x: max |A - FD| ≤ rel_tol · max(|FD|,
/// floor).
inline void expect_jacobian_matches(const Eigen::MatrixXd& analytic, const FdFunction& f,
    const Eigen::VectorXd& x, double rel_tol = 1e-6, double h = 1e-4, double floor = 1e-8) {
  const Eigen::MatrixXd fd = fd_jacobian(f, x, h);
  ASSERT_EQ(analytic.rows(), fd.rows());
  ASSERT_EQ(analytic.cols(), fd.cols());
  const double scale = std::max(fd.cwiseAbs().maxCoeff(), floor);
  Eigen::Index r = 0, c = 0;
  const double err = (analytic - fd).cwiseAbs().maxCoeff(&r, &c);
  EXPECT_LE(err, rel_tol * scale) << "worst entry (" << r << "," << c << "): analytic "
                                  << analytic(r, c) << " vs finite difference " << fd(r, c)
                                  << " (scale " << scale << ")";
}

} // namespace elastolearn::test
