// The corrected learned simulators against the reference mass-spring system.
#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/implicit_simulator.hpp>
#include <elastolearn/springs/reference_simulator.hpp>
#include <elastolearn/springs/stability.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::springs;

namespace {
LearnedSpring linear_spring(double k, double c) {
  TrainingOptions t;
  t.law.k = k;
  t.law.c = c;
  if (k * t.dt * t.dt >= 3.5) {
    t.sampling = SamplingKind::phase_grid;
    t.steps = 20;
  }
  return learn_spring(t);
}

/// Max over `steps` steps of the position difference between two steppers from one state.
double max_trajectory_difference(
    SpringStepper& a, SpringStepper& b, const SpringState& start, int steps) {
  SpringState sa = start, sb = start;
  double worst = 0.0;
  for (int s = 0; s < steps; ++s) {
    a.step(sa);
    b.step(sb);
    worst = std::max(worst, (sa.x - sb.x).cwiseAbs().maxCoeff());
  }
  return worst;
}
} // namespace

TEST(ExplicitLearned, TrajectoriesEqualTheReferenceSystem) {
  const StabilityCase cases[] = { single_spring_case(0.3), rope_case(10), hanging_cloth_case(8) };
  for (const StabilityCase& test : cases) {
    for (double c : { 0.0, 3.0 }) {
      const double k = 500.0;
      ReferenceSimulator reference(
          test.system, SpringLaw { SpringLawKind::linear, k, c }, 0.01, test.loads);
      ExplicitLearnedSimulator learned(test.system, linear_spring(k, c), 0.01, test.loads);
      // The regression is exact to ~1e-16 relative; over 300 steps of a chaotic-free but
      // oscillating system that round-off stays far below 1e-10 of the unit rest length.
      EXPECT_LT(max_trajectory_difference(reference, learned, test.initial, 300), 1e-10)
          << test.name << " c=" << c;
    }
  }
}

TEST(PaperMode, SingleSpringOscillatesSqrtTwoTooFast) {
  // Linearised paper step for a single spring has trace 2(1 − k dt²) (double position
  // integration) against 2(1 − k dt²/2) for the reference: ω_paper/ω_ref → √2 as dt → 0.
  const double k = 100.0, dt = 0.01;
  const StabilityCase test = single_spring_case(0.01);
  PaperSimulator paper(test.system, linear_spring(k, 0.0), dt);
  SpringState s = test.initial;
  int crossings = 0;
  double previous = s.x(1, 0) - 1.0;
  const int steps = 20000;
  for (int i = 0; i < steps; ++i) {
    paper.step(s);
    const double e = s.x(1, 0) - 1.0;
    if ((e > 0) != (previous > 0))
      ++crossings;
    previous = e;
  }
  const double omega_paper = crossings * M_PI / (steps * dt);
  const double omega_ref = std::acos(1.0 - k * dt * dt / 2.0) / dt;
  // Counting zero crossings over 200 s resolves ω to ~π/200 s ≈ 0.016 rad/s.
  EXPECT_NEAR(omega_paper / omega_ref,
      std::acos(1.0 - k * dt * dt) / std::acos(1.0 - k * dt * dt / 2.0), 0.005);
  EXPECT_NEAR(omega_paper / omega_ref, std::sqrt(2.0), 0.01);
}

TEST(PaperMode, RequiresTheTrainingStep) {
  EXPECT_THROW(PaperSimulator(make_rope(2), linear_spring(100.0, 0.0), 0.005), InputError);
}

TEST(ImplicitLearned, RestsExactlyAtTheReferenceEquilibrium) {
  // A rope with a load: the reference equilibrium (k e = F in each spring) must be a fixed
  // point of the implicit step, to round-off.
  const double k = 1e4, force = 30.0;
  SpringSystem rope = make_rope(6);
  Loads loads;
  loads.forces = Positions::Zero(6, 3);
  loads.forces(5, 0) = force;
  for (LinearSolverKind solver : { LinearSolverKind::direct, LinearSolverKind::cg }) {
    LearnedSimulatorOptions o;
    o.mode = LearnedMode::corrected_implicit;
    o.solver = solver;
    ImplicitLearnedSimulator sim(rope, linear_spring(k, 0.0), 0.01, o, loads);
    SpringState s = rest_state(rope);
    for (int a = 0; a < 6; ++a)
      s.x(a, 0) = a * (1.0 + force / k);
    const SpringState before = s;
    for (int i = 0; i < 10; ++i)
      sim.step(s);
    EXPECT_LT((s.x - before.x).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT(s.v.cwiseAbs().maxCoeff(), 1e-10);
  }
}

TEST(ImplicitLearned, FreeFallIsExact) {
  ClothOptions o;
  o.columns = o.rows = 6;
  o.pins = ClothPins::none;
  const SpringSystem cloth = make_cloth(o);
  Loads loads;
  loads.gravity = Vec3(0.0, -9.81, 0.0);
  LearnedSimulatorOptions options;
  options.mode = LearnedMode::corrected_implicit;
  ImplicitLearnedSimulator sim(cloth, linear_spring(1e5, 1.0), 0.01, options, loads);
  SpringState s = rest_state(cloth);
  const int steps = 100;
  for (int i = 0; i < steps; ++i)
    sim.step(s);
  // Discrete free fall of backward (and semi-implicit) Euler: y_n = −g h² n(n+1)/2.
  const double expected = -9.81 * 0.01 * 0.01 * steps * (steps + 1) / 2.0;
  EXPECT_LT(((s.x.col(1) - cloth.rest.col(1)).array() - expected).abs().maxCoeff(), 1e-11);
  EXPECT_LT((s.x.leftCols<1>() - cloth.rest.leftCols<1>()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ImplicitLearned, StableForVeryStiffCloth) {
  struct Case {
    int n;
    double k;
    int steps;
  };
  for (const Case& c : { Case { 5, 1e6, 300 }, Case { 25, 1e5, 60 } }) {
    const StabilityCase test = hanging_cloth_case(c.n);
    LearnedSimulatorOptions o;
    o.mode = LearnedMode::corrected_implicit;
    ImplicitLearnedSimulator sim(test.system, linear_spring(c.k, 0.0), 0.01, o, test.loads);
    EXPECT_TRUE(run_is_stable(sim, test, c.steps)) << c.n;
    // Stiff springs barely stretch: the maximum strain stays small (gravity load / k).
    SpringState s = test.initial;
    for (int i = 0; i < c.steps; ++i)
      sim.step(s);
    double max_strain = 0.0;
    for (int sp = 0; sp < test.system.spring_count(); ++sp) {
      const double length
          = (s.x.row(test.system.springs(sp, 0)) - s.x.row(test.system.springs(sp, 1))).norm();
      max_strain = std::max(max_strain, std::abs(length / test.system.rest_lengths[sp] - 1.0));
    }
    EXPECT_LT(max_strain, 0.05) << c.n;
  }
}

TEST(ImplicitLearned, DirectAndCgSolversAgree) {
  const StabilityCase test = hanging_cloth_case(6);
  LearnedSimulatorOptions o;
  o.mode = LearnedMode::corrected_implicit;
  o.solver = LinearSolverKind::direct;
  ImplicitLearnedSimulator direct(test.system, linear_spring(2e3, 1.0), 0.01, o, test.loads);
  o.solver = LinearSolverKind::cg;
  o.cg_tolerance = 1e-12;
  ImplicitLearnedSimulator cg(test.system, linear_spring(2e3, 1.0), 0.01, o, test.loads);
  EXPECT_TRUE(direct.uses_direct_solver());
  EXPECT_FALSE(cg.uses_direct_solver());
  // CG to 1e-12 relative residual: trajectories agree to well below 1e-8 over 50 steps.
  EXPECT_LT(max_trajectory_difference(direct, cg, test.initial, 50), 1e-8);
  EXPECT_TRUE(cg.last_step().converged);
}

TEST(SpringSystem, RejectsBadTopology) {
  SpringSystem sys;
  sys.rest = Positions::Zero(2, 3);
  sys.rest(1, 0) = 1.0;
  sys.springs.resize(1, 2);
  sys.springs << 0, 2;
  EXPECT_THROW(sys.finalize(), InputError);
  sys.springs << 0, 0;
  EXPECT_THROW(sys.finalize(), InputError);
  sys.springs.resize(2, 2);
  sys.springs << 0, 1, 1, 0;
  EXPECT_THROW(sys.finalize(), InputError);
  sys.springs.resize(1, 2);
  sys.springs << 0, 1;
  sys.rest(1, 0) = 0.0; // zero rest length
  EXPECT_THROW(sys.finalize(), InputError);
}
