// The backward-Euler simulator: physics it must reproduce and contracts it must keep.
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>
#include <elastolearn/sim/newton.hpp>
#include <elastolearn/sim/run_simulation.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <support/bar_scene.hpp>

#include <cmath>
#include <gtest/gtest.h>
#include <numbers>

using namespace elastolearn;

namespace {

double mean_tip_y(const mesh::TetMesh& mesh, const VecX& x) {
  const auto tip = mesh::vertices_with_max_coordinate(mesh, 0, 1e-9);
  double sum = 0;
  for (int v : tip)
    sum += x[3 * v + 1] - mesh.rest_positions()(v, 1);
  return sum / tip.size();
}

} // namespace

class SolverBackends : public ::testing::TestWithParam<sim::LinearSolverType> { };

TEST_P(SolverBackends, AllBackendsGiveTheSameDynamicSteps) {
  // Reference: CHOLMOD. Each backend converges Newton to 1e-10 relative, so states agree to
  // ~1e-9 of the displacement.
  auto run = [](sim::LinearSolverType type) {
    auto s = test::bar_scene({ .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
    s.linear_solver = type;
    s.newton.relative_tolerance = 1e-10;
    sim::Simulator sim(s);
    for (int i = 0; i < 20; ++i)
      EXPECT_TRUE(sim.step().converged);
    return VecX(sim.positions() - flatten(s.mesh.rest_positions()));
  };
  const VecX reference = run(sim::LinearSolverType::Cholmod);
  const VecX other = run(GetParam());
  ASSERT_GT(reference.norm(), 1e-6);
  EXPECT_LT((other - reference).norm(), 1e-7 * reference.norm());
}

INSTANTIATE_TEST_SUITE_P(Sim, SolverBackends,
    ::testing::Values(sim::LinearSolverType::Cholmod, sim::LinearSolverType::ConjugateGradient,
        sim::LinearSolverType::EigenLdlt),
    [](const auto& info) {
      auto n = sim::to_string(info.param);
      return n == "eigen-ldlt" ? std::string("EigenLdlt") : n;
    });

TEST(Newton, JacobianReuseMeetsTheSameToleranceWithFewerAssemblies) {
  // Dynamics: after Newton's first step leaves ~1e-3 of the residual, the chord step with the
  // same Jacobian converges too; states must agree with full Newton to the solve's accuracy
  // (both to 1e-10 relative residual) while assembling fewer Jacobians.
  struct Run {
    VecX displacement;
    int iterations = 0, jacobians = 0;
  };
  auto run = [](double reuse_contraction) {
    auto s = test::bar_scene({ .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
    s.newton.relative_tolerance = 1e-10;
    s.newton.jacobian_reuse_contraction = reuse_contraction;
    sim::Simulator sim(s);
    Run out;
    for (int i = 0; i < 30; ++i) {
      const auto report = sim.step();
      EXPECT_TRUE(report.converged) << report.message;
      out.iterations += report.iterations;
      out.jacobians += report.jacobians;
    }
    out.displacement = sim.positions() - flatten(s.mesh.rest_positions());
    return out;
  };
  const Run full = run(0), reuse = run(10);
  EXPECT_EQ(full.jacobians, full.iterations);
  EXPECT_LT(reuse.jacobians, full.jacobians);
  EXPECT_LE(reuse.iterations, full.iterations + 30); // at most one more iteration per step
  ASSERT_GT(full.displacement.norm(), 1e-6);
  EXPECT_LT((reuse.displacement - full.displacement).norm(), 1e-7 * full.displacement.norm());
}

TEST(Newton, AStepStartedFromExtrapolatedVelocitiesNeedsFewerIterationsForTheSameState) {
  // The swinging bar under gravity: Newton starts each step from v + (v − v_before) instead of
  // v. At the default tolerance the run must take fewer iterations (180 → 167 when written);
  // converged tightly (1e-10 relative) both runs must reach the same states to the solve's
  // accuracy.
  auto run = [](bool extrapolate, double tolerance) {
    auto s = test::swinging_bar(60);
    s.newton.extrapolate_velocity = extrapolate;
    s.newton.relative_tolerance = tolerance;
    sim::Simulator sim(s);
    EXPECT_TRUE(sim.apply_initial_condition().converged);
    int iterations = 0;
    for (int i = 0; i < 60; ++i) {
      const auto report = sim.step();
      EXPECT_TRUE(report.converged) << report.message;
      iterations += report.iterations;
    }
    return std::make_pair(iterations, VecX(sim.positions() - flatten(s.mesh.rest_positions())));
  };
  const auto [plain_iterations, plain] = run(false, 1e-6);
  const auto [extrapolated_iterations, extrapolated] = run(true, 1e-6);
  std::printf("  iterations over 60 steps: %d from v, %d extrapolated\n", plain_iterations,
      extrapolated_iterations);
  EXPECT_LT(extrapolated_iterations, plain_iterations);
  const VecX tight_plain = run(false, 1e-10).second, tight_extrapolated = run(true, 1e-10).second;
  ASSERT_GT(tight_plain.norm(), 1e-6);
  EXPECT_LT((tight_extrapolated - tight_plain).norm(), 1e-7 * tight_plain.norm());
  EXPECT_LT((extrapolated - plain).norm(), 1e-4 * plain.norm()); // default tolerance: close too
}

TEST(Newton, AStateSetFromOutsideHasNoPreviousStepToExtrapolate) {
  // After set_state the next step must start from the state's own velocities, exactly as a fresh
  // simulator set to that state does: the velocities before the set state are another motion's.
  auto s = test::bar_scene({ .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
  s.newton.extrapolate_velocity = true;
  sim::Simulator moving(s);
  for (int i = 0; i < 10; ++i)
    ASSERT_TRUE(moving.step().converged);
  const VecX x = moving.positions(), v = 0.5 * moving.velocities();
  moving.set_state(x, v, 0.0);
  sim::Simulator fresh(s);
  fresh.set_state(x, v, 0.0);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(moving.step().converged);
    ASSERT_TRUE(fresh.step().converged);
  }
  EXPECT_EQ(moving.positions(), fresh.positions());
}

TEST(Newton, JacobianIsRefreshedWhenAChordStepContractsLittle) {
  // A geometrically nonlinear static solve (tip droop ~ 30 % of the length): iterations far from
  // the solution contract little, so they must assemble afresh; reusing every Jacobian would
  // leave Newton crawling linearly. Reuse may cost an iteration here and there, not many.
  auto run = [](double reuse_contraction) {
    auto s = test::bar_scene({ .young = 2e4, .poisson = 0.3 });
    s.newton.jacobian_reuse_contraction = reuse_contraction;
    sim::Simulator sim(s);
    const auto report = sim.solve_static(1);
    EXPECT_TRUE(report.converged) << report.message;
    EXPECT_GT(-mean_tip_y(s.mesh, sim.positions()), 0.05);
    return report;
  };
  const auto full = run(0), reuse = run(10);
  EXPECT_GE(full.iterations, 4);
  EXPECT_GT(reuse.jacobians, 1);
  EXPECT_LE(reuse.iterations, full.iterations + 3);
}

TEST(Newton, ASolveTheProjectedTangentCannotFinishIsRetriedWithTheExactOne) {
  // The large-droop static solve: elements in compression have indefinite tangents, whose PSD
  // projection slows Newton to linear convergence near the solution. With one iteration fewer
  // than the projected solve needs, the retry with the exact tangent (quadratic near the
  // solution, where the assembled exact Jacobian is positive definite) must reach the same
  // equilibrium; without the retry the solve fails. The retry resumes where the projected solve
  // stopped, so it needs a few iterations, not a solve from the start.
  auto s = test::bar_scene({ .young = 2e4, .poisson = 0.3 });
  s.newton.relative_tolerance = 1e-10;
  s.newton.jacobian_reuse_contraction = 0;
  s.newton.retry_exact_tangent = false;
  sim::Simulator projected(s);
  const auto reference = projected.solve_static(1);
  ASSERT_TRUE(reference.converged) << reference.message;
  std::printf("  projected tangent: %d iterations\n", reference.iterations);
  ASSERT_GE(reference.iterations, 3);

  s.newton.max_iterations = reference.iterations - 1;
  sim::Simulator strict(s);
  EXPECT_FALSE(strict.solve_static(1).converged);
  s.newton.retry_exact_tangent = true;
  sim::Simulator retried(s);
  const auto report = retried.solve_static(1);
  ASSERT_TRUE(report.converged) << report.message;
  std::printf("  retried: %d iterations in all\n", report.iterations);
  EXPECT_LE(report.iterations, reference.iterations - 1 + 3);
  const double droop = -mean_tip_y(s.mesh, projected.positions());
  EXPECT_GT(droop, 0.05);
  EXPECT_LE((retried.positions() - projected.positions()).cwiseAbs().maxCoeff(), 1e-8 * droop);
}

TEST(Newton, ASolveThatCyclesStopsAsStalled) {
  // g(u) = sign(u) √|u| per component: Newton's step u − g/g' = −u cycles between ±u with a
  // constant residual, never converging. With stall_iterations = 5 the solve stops after the
  // fifth iteration without a new lowest residual, naming the stall; with 0 it runs to
  // max_iterations.
  Tets tets(1, 4);
  tets << 0, 1, 2, 3;
  const fem::DofMap dofs(4, { 1, 2, 3 }); // vertex 0 free: three unknowns
  fem::SystemMatrix A(tets, dofs);
  const auto solver = sim::make_linear_solver(sim::LinearSolverType::Cholmod);
  solver->analyze(A.matrix());
  sim::NewtonProblem problem;
  problem.residual = [](const VecX& u, VecX& g) {
    g = u.unaryExpr([](double x) { return std::copysign(std::sqrt(std::abs(x)), x); });
  };
  problem.jacobian = [](const VecX& u, fem::SystemMatrix& J) {
    J.set_zero();
    J.add_diagonal(u.unaryExpr([](double x) { return 0.5 / std::sqrt(std::abs(x)); }));
  };
  auto solve = [&](int stall_iterations) {
    sim::NewtonOptions options;
    options.max_iterations = 100;
    options.stall_iterations = stall_iterations;
    VecX u = Vec3(0.5, -0.2, 0.3);
    return sim::newton_solve(problem, u, A, *solver, options);
  };
  const sim::NewtonReport stalled = solve(5);
  EXPECT_FALSE(stalled.converged);
  EXPECT_EQ(stalled.iterations, 5);
  EXPECT_NE(stalled.message.find("stalled"), std::string::npos) << stalled.message;
  const sim::NewtonReport capped = solve(0);
  EXPECT_FALSE(capped.converged);
  EXPECT_EQ(capped.iterations, 100);
  EXPECT_NE(capped.message.find("no convergence in 100"), std::string::npos) << capped.message;
}

TEST(Statics, CantileverTipDeflectionConvergesToBeamTheory) {
  // Cantilever L = 1, square section a = 0.1 (L/a = 10), ν = 0 (no Poisson stiffening), under
  // its own weight q = ρ g a²: δ = q L⁴/(8 E I) (Euler–Bernoulli) + q L²/(2 κ G A) (Timoshenko
  // shear, 0.8 % here; κ = 5/6, G = E/2). E = 1e9 keeps δ/L ≈ 0.15 %, so the response is linear.
  // Linear tets lock in bending: the error must fall with refinement and be within 5 % at the
  // finest mesh (10 cells through the thickness, 60k tets).
  const double L = 1, a = 0.1, E = 1e9, rho = 1000, g = 9.81;
  const double q = rho * g * a * a, I = std::pow(a, 4) / 12, G = E / 2, kappa = 5.0 / 6.0;
  const double theory = q * std::pow(L, 4) / (8 * E * I) + q * L * L / (2 * kappa * G * a * a);
  double previous_error = INFINITY;
  for (int n : { 2, 4, 10 }) {
    auto s = test::bar_scene({ .size = { L, a, a },
        .cells = { 10 * n, n, n },
        .young = E,
        .poisson = 0.0,
        .density = rho });
    sim::Simulator sim(s);
    const auto report = sim.solve_static(1);
    ASSERT_TRUE(report.converged) << report.message;
    const double deflection = -mean_tip_y(s.mesh, sim.positions());
    const double error = std::abs(deflection - theory) / theory;
    std::printf("  cantilever, %d cells through (%d tets): tip %.5e m, theory %.5e m, error %.2f "
                "%%, %d Newton iterations\n",
        n, s.mesh.num_tets(), deflection, theory, 100 * error, report.iterations);
    EXPECT_LT(error, previous_error);
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.05);
}

TEST(Statics, ASceneThatStepsWithCgFindsItsEquilibriumByADirectFactorisation) {
  // A slender cantilever (L/a = 100) of 200 × 1 × 1 cubes: its stiffness matrix, without the
  // mass term that keeps dynamics well conditioned, spans the bending and axial stiffness
  // (condition ~ (L/a)² times the mesh's), beyond what Jacobi-CG solves to Newton's tolerances in
  // its iteration cap. A scene that chose CG for its steps must still find its static equilibrium
  // under gravity, and the same one as with CHOLMOD.
  auto equilibrium = [](sim::LinearSolverType type) {
    auto s = test::bar_scene(
        { .size = { 2, 0.02, 0.02 }, .cells = { 200, 1, 1 }, .young = 1e10, .poisson = 0.3 });
    s.linear_solver = type;
    sim::Simulator sim(s);
    const auto report = sim.solve_static(1);
    EXPECT_TRUE(report.converged) << sim::to_string(type) << ": " << report.message;
    return VecX(sim.positions() - flatten(s.mesh.rest_positions()));
  };
  const VecX direct = equilibrium(sim::LinearSolverType::Cholmod);
  const VecX cg = equilibrium(sim::LinearSolverType::ConjugateGradient);
  ASSERT_GT(direct.norm(), 1e-3);
  EXPECT_LT((cg - direct).norm(), 1e-8 * direct.norm());
}

TEST(Dynamics, DampedModeDecaysAtRayleighRate) {
  // Linear regime: a clamped bar released from a small tip load vibrates in its first bending
  // mode; for modal Rayleigh damping the mode obeys ẍ + c ẋ + ω² x = 0 with c = α₀ + α₁ ω².
  // Backward Euler turns this into (1 + hc + h²ω²) z² − (2 + hc) z + 1 = 0 for the per-step
  // factor z = r e^{iθ}, so the measured r and θ give c and ω exactly:
  //   hc = 2 cos θ / r − 2,   h²ω² = 1/r² − 1 − hc.
  // The section is rectangular (0.05 × 0.1) so the y- and z-bending modes do not share a
  // frequency and cannot trade energy; E = 3e7 puts ω near 100 rad/s.
  const double alpha0 = 1.0, alpha1 = 0.002, h = 2e-4;
  auto s = test::bar_scene({ .size = { 0.4, 0.05, 0.1 },
      .cells = { 8, 1, 2 },
      .young = 3e7,
      .poisson = 0.3,
      .alpha0 = alpha0,
      .alpha1 = alpha1 });
  s.gravity.setZero();
  s.dt = h;
  s.initial.kind = sim::InitialCondition::Kind::StaticLoad;
  s.initial.static_loads.push_back(
      { mesh::vertices_with_max_coordinate(s.mesh, 0, 1e-9), Vec3(0, -1.0, 0) });
  sim::Simulator sim(s);
  const auto initial = sim.apply_initial_condition();
  ASSERT_TRUE(initial.converged) << initial.message;
  std::vector<double> t, y;
  for (int i = 0; i < 4000; ++i) {
    const auto r = sim.step();
    ASSERT_TRUE(r.converged) << "step " << i << ": " << r.message;
    t.push_back(sim.time());
    y.push_back(mean_tip_y(s.mesh, sim.positions()));
  }
  // Peaks: local maxima of y, interpolated by a parabola through the three samples.
  std::vector<std::pair<double, double>> peaks;
  for (size_t i = 1; i + 1 < y.size(); ++i)
    if (y[i] > y[i - 1] && y[i] >= y[i + 1] && y[i] > 0) {
      const double d = 0.5 * (y[i - 1] - y[i + 1]) / (y[i - 1] - 2 * y[i] + y[i + 1]);
      peaks.emplace_back(t[i] + d * h, y[i] - 0.25 * (y[i - 1] - y[i + 1]) * d);
    }
  ASSERT_GE(peaks.size(), 4u);
  const double span = peaks.back().first - peaks.front().first;
  const double theta = 2 * std::numbers::pi * (peaks.size() - 1) / span * h;
  const double r = std::exp(std::log(peaks.back().second / peaks.front().second) / span * h);
  const double hc = 2 * std::cos(theta) / r - 2;
  const double omega = std::sqrt(1 / (r * r) - 1 - hc) / h;
  const double measured = hc / h, predicted = alpha0 + alpha1 * omega * omega;
  std::printf("  mode ω = %.2f rad/s: damping coefficient measured %.4f 1/s, Rayleigh α₀ + α₁ω² = "
              "%.4f 1/s\n",
      omega, measured, predicted);
  // 2 %: peak interpolation and the weak coupling to other modes of a coarse, asymmetric mesh.
  EXPECT_NEAR(measured, predicted, 0.02 * predicted);
}

TEST(Dynamics, UndampedMotionNeverGainsEnergy) {
  // Backward Euler is dissipative: kinetic + elastic energy never increases without damping or
  // external work (gravity off, fixed base). Tolerance: Newton residual 1e-10 relative.
  auto s = test::bar_scene({ .young = 3e5 });
  s.gravity.setZero();
  s.material.elastic
      = std::make_shared<material::NeoHookeanModel>(material::Lame::from_young_poisson(3e5, 0.4));
  s.newton.relative_tolerance = 1e-10;
  s.initial.kind = sim::InitialCondition::Kind::Velocity;
  s.initial.angular_velocity = Vec3(0, 0, 3.0);
  s.initial.center = Vec3(0, 0.05, 0.05);
  sim::Simulator sim(s);
  sim.apply_initial_condition();
  double energy = sim.kinetic_energy() + sim.elastic_energy();
  ASSERT_GT(energy, 0);
  for (int i = 0; i < 200; ++i) {
    ASSERT_TRUE(sim.step().converged);
    const double e = sim.kinetic_energy() + sim.elastic_energy();
    EXPECT_LE(e, energy * (1 + 1e-9)) << "step " << i;
    energy = e;
  }
}

TEST(Dynamics, KeyframedVerticesFollowTheirMotionAndFixedOnesStay) {
  auto s = test::bar_scene({ .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
  sim::KeyframeMotion k;
  k.vertices = mesh::vertices_with_max_coordinate(s.mesh, 0, 1e-9);
  k.amplitude = Vec3(0, 0.02, 0);
  k.frequency = 2;
  s.keyframes.push_back(k);
  sim::Simulator sim(s);
  for (int i = 0; i < 100; ++i)
    ASSERT_TRUE(sim.step().converged);
  const Vec3 offset = k.offset_at(sim.time());
  for (int v : k.vertices)
    EXPECT_LT(
        (sim.positions().segment<3>(3 * v) - s.mesh.rest_positions().row(v).transpose() - offset)
            .norm(),
        1e-12);
  for (int v : s.fixed_vertices)
    EXPECT_EQ(
        (sim.positions().segment<3>(3 * v) - s.mesh.rest_positions().row(v).transpose()).norm(),
        0.0);
}

TEST(Dynamics, ConsistentMassAgreesWithLumpedOnSmoothMotion) {
  // Same physics, different mass discretisation: tip sag after 0.1 s agrees within a few percent.
  auto lumped = test::bar_scene({ .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
  auto consistent = lumped;
  consistent.mass = fem::MassType::Consistent;
  sim::Simulator a(lumped), b(consistent);
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(a.step().converged);
    ASSERT_TRUE(b.step().converged);
  }
  const double ya = mean_tip_y(lumped.mesh, a.positions()),
               yb = mean_tip_y(lumped.mesh, b.positions());
  ASSERT_LT(ya, -1e-3);
  EXPECT_NEAR(yb, ya, 0.05 * std::abs(ya));
}

TEST(Dynamics, CorrectionHookChangesTheMotionAndNewtonStillConverges) {
  // A stiffening correction must reduce the sag; the integrator uses its force and tangent.
  auto base = test::bar_scene({ .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
  auto corrected = base;
  material::AnalyticCorrection::Parameters p;
  p.a = 1e8; // (σ−1)³ stiffening: ~100 Pa at 1 % strain vs E·ε ≈ 3e3 Pa
  p.b = 1; // viscous term [Pa·s]
  p.c = 10;
  corrected.material.correction = std::make_shared<material::AnalyticCorrection>(p);
  sim::Simulator a(base), b(corrected);
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(a.step().converged);
    const auto r = b.step();
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_LE(r.iterations, 10);
    if (i % 20 == 0)
      std::printf("  step %d: %d Newton iterations\n", i, r.iterations);
  }
  EXPECT_GT(
      std::abs(mean_tip_y(base.mesh, a.positions()) - mean_tip_y(base.mesh, b.positions())), 1e-6);
}

TEST(Divergence, StopsWithAMessageNamingTheFrameAndKeepsEarlierFrames) {
  // An absurd time step on a stiff bar with a single Newton iteration allowed cannot converge.
  auto s = test::bar_scene({ .young = 3e5 });
  s.newton.max_iterations = 1;
  s.newton.relative_tolerance = 1e-12;
  s.newton.max_step_halvings = 0; // substeps would not help either, but cost 15× the time
  s.newton.retry_exact_tangent = false; // resumed where it stopped, Newton would converge
  s.frames = 50;
  int frames_seen = 0;
  const auto report
      = sim::run_simulation(s, [&](int, double, const VecX&, const VecX&) { ++frames_seen; });
  EXPECT_FALSE(report.completed);
  EXPECT_NE(report.message.find("frame 1"), std::string::npos) << report.message;
  EXPECT_EQ(frames_seen, report.frames_written);
  EXPECT_EQ(frames_seen, 1);
}

/// A soft bar falling under gravity with three Newton iterations to a 1e-10 relative tolerance
/// and no exact-tangent retry: some step before frame 40 fails whole and converges in substeps.
static sim::Scene soft_bar_needing_substeps() {
  auto s = test::bar_scene({ .size = { 0.2, 0.04, 0.04 },
      .cells = { 10, 2, 2 },
      .young = 1e5,
      .poisson = 0.3,
      .dt = 2e-3 });
  s.newton.max_iterations = 3;
  s.newton.relative_tolerance = 1e-10;
  s.newton.jacobian_reuse_contraction = 0;
  s.newton.retry_exact_tangent = false; // substeps alone
  return s;
}

TEST(Substeps, AStepNewtonCannotSolveWholeIsBackwardEulerInEqualSubsteps) {
  // Three Newton iterations to a 1e-10 relative tolerance on a soft bar falling under gravity:
  // some step fails whole (measured: the first before frame 40) and converges in substeps, whose
  // problems are closer to linear. The state after it must be that of a simulator with the
  // substep length run from the same state for as many steps, and the step must end on the
  // frame's time.
  auto s = soft_bar_needing_substeps();
  sim::Simulator whole(s);
  sim::NewtonReport report;
  VecX x_before, v_before;
  double t_before = 0;
  for (int i = 0; i < 60 && report.substeps == 1; ++i) {
    x_before = whole.positions();
    v_before = whole.velocities();
    t_before = whole.time();
    report = whole.step();
    ASSERT_TRUE(report.converged) << "step " << i << ": " << report.message;
  }
  ASSERT_GT(report.substeps, 1) << "no step needed substeps: the test no longer tests them";
  EXPECT_NEAR(whole.time(), whole.step_index() * s.dt, 1e-15);

  auto fine = s;
  fine.dt = s.dt / report.substeps;
  fine.newton.max_step_halvings = 0;
  sim::Simulator reference(fine);
  reference.set_state(x_before, v_before, t_before);
  for (int i = 0; i < report.substeps; ++i)
    ASSERT_TRUE(reference.step().converged);
  // Both solve the same equations to the same tolerance (1e-10 of each substep's residual).
  const double scale = reference.positions().cwiseAbs().maxCoeff();
  EXPECT_LE((whole.positions() - reference.positions()).cwiseAbs().maxCoeff(), 1e-9 * scale);
  EXPECT_LE((whole.velocities() - reference.velocities()).cwiseAbs().maxCoeff(),
      1e-6 * reference.velocities().cwiseAbs().maxCoeff());

  // Without the retry the same step fails and leaves the state where it was.
  auto strict_scene = s;
  strict_scene.newton.max_step_halvings = 0;
  sim::Simulator strict(strict_scene);
  strict.set_state(x_before, v_before, t_before);
  EXPECT_FALSE(strict.step().converged);
  EXPECT_EQ(strict.positions(), x_before);
  EXPECT_EQ(strict.time(), t_before);
}

TEST(Substeps, AStepThatConvergesWholeIsNeverSplit) {
  const auto s = test::bar_scene({ .young = 3e5 });
  auto strict = s;
  strict.newton.max_step_halvings = 0;
  sim::Simulator a(s), b(strict);
  for (int i = 0; i < 20; ++i) {
    const auto r = a.step();
    ASSERT_TRUE(r.converged);
    EXPECT_EQ(r.substeps, 1);
    ASSERT_TRUE(b.step().converged);
  }
  EXPECT_EQ(a.positions(), b.positions());
}

TEST(Substeps, ARunReportsTheFirstFrameThatNeededThem) {
  // The soft bar of the test above: the run completes with substeps, and names the first frame
  // that needed them, the frame at which the same run without them stops.
  auto s = soft_bar_needing_substeps();
  s.frames = 60;
  const auto run = sim::run_simulation(s, {});
  ASSERT_TRUE(run.completed) << run.message;
  ASSERT_GE(run.substepped_frames, 1);
  s.newton.max_step_halvings = 0;
  const auto strict = sim::run_simulation(s, {});
  EXPECT_FALSE(strict.completed);
  EXPECT_EQ(strict.frames_written, run.first_substepped_frame); // frames 0 .. first − 1
}
