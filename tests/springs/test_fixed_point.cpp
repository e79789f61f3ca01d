#include <elastolearn/springs/fixed_point.hpp>
#include <elastolearn/springs/learned_simulator.hpp>
#include <elastolearn/springs/reference_simulator.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::springs;

TEST(FixedPoint, ReferenceRopeEquilibriumIsTheForceBalance) {
  const double k = 300.0, force = 12.0;
  SpringSystem rope = make_rope(5);
  Loads loads;
  loads.forces = Positions::Zero(5, 3);
  loads.forces(4, 0) = force;
  ReferenceSimulator sim(rope, SpringLaw { SpringLawKind::linear, k }, 0.01, loads);
  SpringState s = rest_state(rope);
  const FixedPointResult r = solve_fixed_point(sim, s);
  ASSERT_TRUE(r.converged) << r.message;
  for (int a = 0; a < 5; ++a)
    EXPECT_NEAR(s.x(a, 0), a * (1.0 + force / k), 1e-12);
  EXPECT_LT(s.v.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(FixedPoint, PaperSingleSpringHasTheDerivedNonzeroVelocity) {
  // Derivation (docs/springs.md): the paper step's fixed point under load F has
  // v = −dt F / 2 and elongation e = F/k − dt² F / 2.
  const double k = 500.0, force = 20.0, dt = 0.01;
  TrainingOptions t;
  t.law.k = k;
  SpringSystem spring = make_rope(2);
  Loads loads;
  loads.forces = Positions::Zero(2, 3);
  loads.forces(1, 0) = force;
  PaperSimulator sim(spring, learn_spring(t), dt, loads);
  SpringState s = rest_state(spring);
  FixedPointOptions o;
  o.components = { true, false, false };
  const FixedPointResult r = solve_fixed_point(sim, s, o);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(s.v(1, 0), -dt * force / 2.0, 1e-12);
  EXPECT_NEAR(s.x(1, 0) - 1.0, force / k - dt * dt * force / 2.0, 1e-12);
}

TEST(FixedPoint, ColouredJacobianWorksOnCloth) {
  // A 2-D cloth under load: the coloured finite-difference Newton converges to round-off.
  ClothOptions o;
  o.columns = o.rows = 7;
  const SpringSystem cloth = make_cloth(o);
  Loads loads;
  loads.gravity = Vec3(0, -1.0, 0);
  ReferenceSimulator sim(cloth, SpringLaw { SpringLawKind::linear, 200.0 }, 0.01, loads);
  SpringState s = rest_state(cloth);
  FixedPointOptions fp;
  fp.components = { true, true, false };
  const FixedPointResult r = solve_fixed_point(sim, s, fp);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LE(r.iterations, 12);
  SpringState next = s;
  sim.step(next);
  EXPECT_LT((next.x - s.x).cwiseAbs().maxCoeff(), 1e-12);
}
