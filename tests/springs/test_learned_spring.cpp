#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/learned_spring.hpp>

#include "support/finite_difference.hpp"

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::springs;

namespace {
TrainingOptions linear_training(double k, double c, double dt = 0.01) {
  TrainingOptions t;
  t.law.k = k;
  t.law.c = c;
  t.dt = dt;
  return t;
}
} // namespace

// The regression must recover the analytic one-step map of semi-implicit Euler (paper Eq. 3,
// with its damping entry corrected: Δe = −k dt² e + dt (1 − c dt) v, Δv = −k dt e − c dt v).
TEST(LearnedSpring, CoefficientsEqualTheAnalyticOneStepMap) {
  for (double k : { 100.0, 1000.0 }) {
    for (double c : { 0.0, 2.0 }) {
      const double dt = 0.01;
      const LearnedSpring spring = learn_spring(linear_training(k, c, dt));
      const MatX& b = spring.coefficients();
      // Noise-free linear data: exact to round-off relative to the largest coefficient.
      const double tol = 1e-12 * std::max(1.0, k * dt);
      EXPECT_NEAR(b(0, 0), 0.0, tol);
      EXPECT_NEAR(b(1, 0), -k * dt * dt, tol);
      EXPECT_NEAR(b(2, 0), dt * (1.0 - c * dt), tol);
      EXPECT_NEAR(b(0, 1), 0.0, tol);
      EXPECT_NEAR(b(1, 1), -k * dt, tol);
      EXPECT_NEAR(b(2, 1), -c * dt, tol);
      EXPECT_NEAR(spring.report().r_squared[1], 1.0, 1e-12);
      EXPECT_LT(spring.report().max_residual[1], 1e-12);
      // The learned force is the reference law.
      EXPECT_NEAR(spring.force(0.3, -0.7), -k * 0.3 + c * 0.7, 1e-9 * k);
    }
  }
}

TEST(LearnedSpring, PhaseGridSamplingLearnsStiffSpringsTrajectoriesCannot) {
  TrainingOptions t = linear_training(1e6, 0.0);
  EXPECT_THROW(generate_training_set(t), InputError); // k dt² = 100: the 1-D run diverges
  t.sampling = SamplingKind::phase_grid;
  t.steps = 20;
  const LearnedSpring spring = learn_spring(t);
  EXPECT_NEAR(spring.force(0.01, 0.0), -1e4, 1e-6);
}

TEST(LearnedSpring, CubicSpringIsLearnedExactlyByCubicFeatures) {
  TrainingOptions t = linear_training(100.0, 0.5);
  t.law.kind = SpringLawKind::cubic;
  t.law.k3 = 400.0;
  LearnOptions o;
  o.features.degree = 3;
  const LearnedSpring spring = learn_spring(t, o);
  for (double e : { -0.4, -0.1, 0.0, 0.2, 0.45 })
    for (double v : { -1.0, 0.0, 2.0 })
      // Δv of a cubic law is a cubic polynomial in (e, v): the fit is exact up to round-off.
      EXPECT_NEAR(spring.force(e, v), t.law.force(e, v), 1e-8);
  // The linear paper model cannot represent it.
  const LearnedSpring linear = learn_spring(t);
  EXPECT_GT(std::abs(linear.force(0.45, 0.0) - t.law.force(0.45, 0.0)), 1.0);
}

TEST(LearnedSpring, BilinearSpringIsLearnedBySplineFeatures) {
  TrainingOptions t = linear_training(200.0, 0.0);
  t.law.kind = SpringLawKind::bilinear;
  t.law.k_compression = 20.0;
  t.sampling = SamplingKind::phase_grid;
  t.steps = 41;
  LearnOptions o;
  o.features.kind = FeatureKind::spline;
  o.features.knots = uniform_knots(-0.5, 0.5, 11); // 0 is a knot
  const LearnedSpring spring = learn_spring(t, o);
  for (double e : { -0.45, -0.2, -0.01, 0.01, 0.3 })
    EXPECT_NEAR(spring.force(e, 0.5), t.law.force(e, 0.5), 1e-8); // piecewise linear: exact
}

TEST(LearnedSpring, ForceSlopesMatchFiniteDifferences) {
  TrainingOptions t = linear_training(100.0, 1.0);
  t.law.kind = SpringLawKind::cubic;
  t.law.k3 = 300.0;
  for (FeatureKind kind : { FeatureKind::polynomial, FeatureKind::spline }) {
    LearnOptions o;
    o.features.kind = kind;
    o.features.degree = 4;
    o.features.knots = uniform_knots(-0.5, 0.5, 8);
    const LearnedSpring spring = learn_spring(t, o);
    const test::FdFunction f
        = [&](const VecX& s) { return VecX::Constant(1, spring.force(s[0], s[1])); };
    const VecX s0 = Eigen::Vector2d(0.13, -0.4); // inside a spline interval
    double force = 0, de = 0, dv = 0;
    spring.force_slopes(s0[0], s0[1], force, de, dv);
    EXPECT_DOUBLE_EQ(force, spring.force(s0[0], s0[1]));
    MatX analytic(1, 2);
    analytic << de, dv;
    test::expect_jacobian_matches(analytic, f, s0, 1e-7, 1e-5);
  }
}

TEST(LearnedSpring, RejectsInconsistentModels) {
  FeatureMap features;
  EXPECT_THROW(LearnedSpring(features, MatX::Zero(2, 2), 0.01, 1.0), InputError);
  EXPECT_THROW(LearnedSpring(features, MatX::Zero(3, 2), 0.0, 1.0), InputError);
  features.degree = 0;
  EXPECT_THROW(features.validate(), InputError);
}
