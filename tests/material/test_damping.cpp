// Rayleigh damping models: constant and stretch-dependent coefficients.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/stretch_dependent_rayleigh.hpp>

#include <support/finite_difference.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace elastolearn;
using namespace elastolearn::material;

namespace {
/// α₁ grows from 0.01 s at σ₁ ≤ 1 to 0.05 s at σ₁ ≥ 1.6 (a "bar damping" curve).
StretchDependentRayleigh bar_damping() {
  return StretchDependentRayleigh(
      CubicSpline({ 1.0 }, { 0.2 }), CubicSpline({ 1.0, 1.2, 1.6 }, { 0.01, 0.03, 0.05 }));
}
} // namespace

TEST(RayleighDamping, IsConstant) {
  const RayleighDamping d(0.5, 0.02);
  EXPECT_TRUE(d.is_constant());
  EXPECT_EQ(d.name(), "rayleigh");
  for (double s : { 0.5, 1.0, 3.0 }) {
    EXPECT_EQ(d.coefficients(s).alpha0, 0.5);
    EXPECT_EQ(d.coefficients(s).alpha1, 0.02);
  }
  EXPECT_EQ(d.clone()->coefficients(2.0).alpha1, 0.02);
}

TEST(RayleighDamping, RejectsNegativeOrNonFiniteCoefficients) {
  EXPECT_THROW(RayleighDamping(-0.1, 0.0), InputError);
  EXPECT_THROW(RayleighDamping(0.0, std::nan("")), InputError);
  try {
    RayleighDamping(0.0, -1.0, "scene.damping");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "scene.damping.alpha1");
  }
}

TEST(StretchDependentRayleigh, FollowsItsSplinesAndExtrapolatesConstantly) {
  const StretchDependentRayleigh d = bar_damping();
  EXPECT_FALSE(d.is_constant());
  EXPECT_DOUBLE_EQ(d.coefficients(1.2).alpha1, 0.03);
  EXPECT_DOUBLE_EQ(d.coefficients(0.7).alpha1, 0.01);
  EXPECT_DOUBLE_EQ(d.coefficients(2.5).alpha1, 0.05);
  EXPECT_DOUBLE_EQ(d.coefficients(1.4).alpha0, 0.2);
  EXPECT_GT(d.coefficients(1.4).alpha1, 0.03);
  EXPECT_LT(d.coefficients(1.4).alpha1, 0.05);
  EXPECT_EQ(d.coefficient_derivatives(2.5).alpha1, 0.0);
  EXPECT_DOUBLE_EQ(d.clone()->coefficients(1.4).alpha1, d.coefficients(1.4).alpha1);
}

TEST(StretchDependentRayleigh, DerivativeMatchesFiniteDifference) {
  const StretchDependentRayleigh d = bar_damping();
  for (double s : { 1.05, 1.3, 1.5 }) {
    Eigen::VectorXd in(1);
    in << s;
    test::FdFunction f = [&](const Eigen::VectorXd& y) {
      return Eigen::VectorXd::Constant(1, d.coefficients(y[0]).alpha1);
    };
    // Cubic pieces: FD exact up to rounding; floor 1e-3 s (the coefficient's size).
    test::expect_jacobian_matches(
        Eigen::MatrixXd::Constant(1, 1, d.coefficient_derivatives(s).alpha1), f, in, 1e-9, 1e-4,
        1e-3);
  }
}

TEST(StretchDependentRayleigh, RejectsNegativeSplines) {
  try {
    StretchDependentRayleigh(
        CubicSpline({ 1.0 }, { 0.1 }), CubicSpline({ 1.0, 2.0 }, { 0.01, -0.02 }), "bar.damping");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "bar.damping.alpha1");
  }
}

TEST(StretchPolynomial, HornerValueAndDerivativeAgreeWithTheExpandedForm) {
  const StretchPolynomial p({ 0.2, 1.0, 20.0, -3.0 });
  for (double s : { 0.95, 1.0, 1.04, 1.3 }) {
    const double t = s - 1;
    double v, d;
    p.evaluate(s, v, d);
    EXPECT_NEAR(v, 0.2 + t + 20 * t * t - 3 * t * t * t, 1e-14) << s;
    EXPECT_NEAR(d, 1 + 40 * t - 9 * t * t, 1e-13) << s;
  }
}

TEST(StretchPolynomial, ClampsAtZeroAndRejectsBadCoefficients) {
  const StretchDependentRayleigh d(StretchCurve::constant(0.0), StretchPolynomial({ 0.1, 2.0 }));
  EXPECT_DOUBLE_EQ(d.coefficients(1.1).alpha1, 0.3);
  EXPECT_EQ(d.coefficients(0.9).alpha1, 0.0); // 0.1 − 0.2 < 0
  EXPECT_EQ(d.coefficient_derivatives(0.9).alpha1, 0.0);
  EXPECT_DOUBLE_EQ(d.coefficient_derivatives(1.1).alpha1, 2.0);
  EXPECT_THROW(StretchPolynomial({}), InputError);
  EXPECT_THROW(StretchPolynomial({ 0.1, std::nan("") }), InputError);
}
