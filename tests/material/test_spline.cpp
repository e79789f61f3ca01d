// The C¹ monotone cubic spline behind spline-edited materials and stretch-dependent damping.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/spline.hpp>

#include <support/finite_difference.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace elastolearn;
using namespace elastolearn::material;

namespace {
CubicSpline wavy() {
  return CubicSpline({ 0.5, 0.8, 1.0, 1.4, 2.0 }, { 2.0, 0.5, 0.7, 3.0, 1.0 });
}
} // namespace

TEST(CubicSpline, InterpolatesKnotsAndExtrapolatesConstantly) {
  const CubicSpline s = wavy();
  for (std::size_t k = 0; k < s.knots_x().size(); ++k) {
    EXPECT_DOUBLE_EQ(s.value(s.knots_x()[k]), s.knots_y()[k]);
  }
  for (double x : { -10.0, 0.0, 0.4999 }) {
    EXPECT_EQ(s.value(x), 2.0);
    EXPECT_EQ(s.derivative(x), 0.0);
  }
  for (double x : { 2.0001, 5.0, 1e6 }) {
    EXPECT_EQ(s.value(x), 1.0);
    EXPECT_EQ(s.derivative(x), 0.0);
  }
}

TEST(CubicSpline, DerivativeMatchesFiniteDifference) {
  const CubicSpline s = wavy();
  // Points inside the intervals (a knot within the stencil would see the jump of s″).
  for (double x : { 0.6, 0.71, 0.9, 1.2, 1.33, 1.7, 1.95 }) {
    Eigen::VectorXd in(1);
    in << x;
    test::FdFunction f
        = [&](const Eigen::VectorXd& y) { return Eigen::VectorXd::Constant(1, s.value(y[0])); };
    // Cubic pieces: the 4th-order FD is exact up to rounding (~1e-12).
    test::expect_jacobian_matches(Eigen::MatrixXd::Constant(1, 1, s.derivative(x)), f, in, 1e-9);
  }
}

TEST(CubicSpline, IsContinuouslyDifferentiableAcrossKnotsAndEnds) {
  const CubicSpline s = wavy();
  const double d = 1e-9;
  for (double x : s.knots_x()) {
    EXPECT_NEAR(s.value(x - d), s.value(x + d), 1e-7);
    // s″ is bounded (≲ 1e3 here), so s′ changes by ≲ 1e-6 over 2·1e-9.
    EXPECT_NEAR(s.derivative(x - d), s.derivative(x + d), 1e-5) << "at knot " << x;
  }
}

TEST(CubicSpline, IsMonotoneBetweenKnotsWithoutOvershoot) {
  const CubicSpline s = wavy();
  const auto& x = s.knots_x();
  const auto& y = s.knots_y();
  for (std::size_t k = 0; k + 1 < x.size(); ++k) {
    const double lo = std::min(y[k], y[k + 1]), hi = std::max(y[k], y[k + 1]);
    const double sign = y[k + 1] > y[k] ? 1.0 : -1.0;
    double prev = s.value(x[k]);
    for (int q = 1; q <= 200; ++q) {
      const double v = s.value(x[k] + (x[k + 1] - x[k]) * q / 200.0);
      EXPECT_GE(v, lo - 1e-12);
      EXPECT_LE(v, hi + 1e-12);
      EXPECT_GE(sign * (v - prev), -1e-12);
      prev = v;
    }
  }
  EXPECT_EQ(s.min_value(), 0.5);
  EXPECT_EQ(s.max_value(), 3.0);
}

TEST(CubicSpline, SingleKnotIsConstant) {
  const CubicSpline s({ 1.0 }, { 0.3 });
  EXPECT_EQ(s.value(-5), 0.3);
  EXPECT_EQ(s.value(7), 0.3);
  EXPECT_EQ(s.derivative(1.0), 0.0);
}

TEST(CubicSpline, RejectsInvalidKnotsNamingTheInput) {
  auto expect_error = [](std::vector<double> x, std::vector<double> y, const std::string& needle) {
    try {
      CubicSpline s(std::move(x), std::move(y), "damping.alpha1");
      FAIL() << "expected InputError about " << needle;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), "damping.alpha1");
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error({}, {}, "at least one knot");
  expect_error({ 0, 1 }, { 0 }, "different lengths");
  expect_error({ 0, 1, 1 }, { 0, 1, 2 }, "strictly increasing");
  expect_error({ 0, 2, 1 }, { 0, 1, 2 }, "x[2] = 1");
  expect_error({ 0, std::nan("") }, { 0, 1 }, "not finite");
  expect_error({ 0, 1 }, { 0, INFINITY }, "not finite");
}
