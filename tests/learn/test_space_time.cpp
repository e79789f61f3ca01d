// The sparse reduced space-time optimisation (paper 000 §5.1, Eqs. 2–5): derivatives of its
// objective against finite differences, and what it must recover.
#include <elastolearn/learn/space_time.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <support/bar_scene.hpp>
#include <support/finite_difference.hpp>

#include <gtest/gtest.h>

#include <random>

namespace elastolearn::learn {
namespace {

/// A small clamped bar swinging under gravity. α₁ = 0 and the exact (unprojected) tangent make
/// the Gauss–Newton Jacobian exact, so it can be compared with finite differences.
sim::Scene small_bar(int frames) {
  sim::Scene s = test::bar_scene({ .size = { 0.2, 0.05, 0.05 },
      .cells = { 4, 1, 1 },
      .young = 2e5,
      .poisson = 0.35,
      .alpha0 = 0.5,
      .dt = 5e-3,
      .frames = frames });
  s.newton.relative_tolerance = 1e-10;
  return s;
}

/// A random basis with zero rows at the prescribed vertices, orthonormal columns.
MatX random_basis(const sim::Scene& scene, int modes, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const int n3 = 3 * scene.mesh.num_vertices();
  MatX basis(n3, modes);
  for (int i = 0; i < n3; ++i)
    for (int j = 0; j < modes; ++j)
      basis(i, j) = normal(rng);
  for (int v : scene.prescribed_vertices())
    basis.middleRows(3 * v, 3).setZero();
  return basis.householderQr().householderQ() * MatX::Identity(n3, modes);
}

observe::Observation observe_all_surface(const sim::Scene& scene, const std::vector<VecX>& frames) {
  std::vector<Positions> p;
  for (const auto& x : frames)
    p.emplace_back(unflatten(x));
  return observe::observe_vertices(
      p, scene.dt, observe::select_visible_vertices(scene.mesh, 1.0, 1), 0.0, 1);
}

std::vector<VecX> displaced(const std::vector<VecX>& x, const MatX& basis, const VecX& z) {
  std::vector<VecX> out = x;
  const int r = static_cast<int>(basis.cols());
  for (size_t i = 0; i < x.size(); ++i)
    out[i] += basis * z.segment(static_cast<Eigen::Index>(i) * r, r);
  return out;
}

TEST(SpaceTime, GradientMatchesFiniteDifferences) {
  const sim::Scene scene = small_bar(6);
  const auto run = sim::simulate_positions(scene);
  ASSERT_TRUE(run.completed);
  const MatX basis = random_basis(scene, 4, 3);
  // Data a little off the simulation, and a trajectory off both: all residuals non-zero.
  observe::Observation observed = observe_all_surface(scene, run.positions);
  for (auto& frame : observed.positions)
    frame.array() += 1e-3;
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  VecX z0(static_cast<Eigen::Index>(run.positions.size()) * 4);
  for (auto& v : z0)
    v = 1e-3 * normal(rng);
  const auto origin = displaced(run.positions, basis, z0);

  TrajectoryPhysics physics(scene);
  physics.set_project_tangent(false);
  SpaceTimeProblem problem(physics, basis, scene.frames, run.initial_velocity, observed, 0.7);
  BlockBandedMatrix normal_matrix(scene.frames + 1, 4);
  VecX gradient;
  problem.assemble(origin, normal_matrix, gradient);
  auto objective
      = [&](const VecX& z) { return problem.evaluate(displaced(origin, basis, z)).total(); };
  const VecX zero = VecX::Zero(z0.size());
  const VecX fd = test::fd_gradient(objective, zero, 1e-5);
  // 4th-order differences with step 1e-5 m on an objective of curvature ~s²K²: relative
  // agreement to ~1e-6 is the round-off floor; 1e-5 leaves margin.
  EXPECT_LE((gradient - fd).cwiseAbs().maxCoeff(), 1e-5 * fd.cwiseAbs().maxCoeff());
}

TEST(SpaceTime, NormalMatrixIsGaussNewtonHessianAtASolution) {
  // At a simulated trajectory observed exactly, every residual vanishes, so the Hessian of E
  // equals JᵀJ: the block-banded normal matrix must match finite differences of the gradient.
  const sim::Scene scene = small_bar(5);
  const auto run = sim::simulate_positions(scene);
  ASSERT_TRUE(run.completed);
  const MatX basis = random_basis(scene, 3, 7);
  const auto observed = observe_all_surface(scene, run.positions);
  TrajectoryPhysics physics(scene);
  physics.set_project_tangent(false);
  SpaceTimeProblem problem(physics, basis, scene.frames, run.initial_velocity, observed, 0.3);
  BlockBandedMatrix normal_matrix(scene.frames + 1, 3);
  VecX gradient;
  problem.assemble(run.positions, normal_matrix, gradient);
  const MatX analytic = normal_matrix.to_dense();
  test::FdFunction gradient_at = [&](const VecX& z) {
    BlockBandedMatrix unused(scene.frames + 1, 3);
    VecX g;
    problem.assemble(displaced(run.positions, basis, z), unused, g);
    return g;
  };
  test::expect_jacobian_matches(analytic, gradient_at, VecX::Zero(analytic.rows()), 1e-5, 1e-6);
}

TEST(SpaceTime, RecoversAnObservedSimulationFromAPerturbedStart) {
  const sim::Scene scene = small_bar(20);
  const auto run = sim::simulate_positions(scene);
  ASSERT_TRUE(run.completed);
  const MatX basis = random_basis(scene, 6, 11);
  const auto observed = observe_all_surface(scene, run.positions);
  std::mt19937 rng(2);
  std::normal_distribution<double> normal;
  VecX z0(static_cast<Eigen::Index>(run.positions.size()) * 6);
  for (auto& v : z0)
    v = 2e-3 * normal(rng);
  const auto start = displaced(run.positions, basis, z0);

  TrajectoryPhysics physics(scene);
  SpaceTimeOptions options;
  options.max_iterations = 20;
  options.tolerance = 1e-12;
  const auto result
      = optimize_space_time(physics, basis, start, run.initial_velocity, observed, options);
  EXPECT_LT(result.objective, 1e-8 * result.initial_objective);
  double worst = 0;
  for (size_t i = 0; i < start.size(); ++i)
    worst = std::max(worst, (result.positions[i] - run.positions[i]).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-6)
      << "the optimum is the simulated trajectory (2 mm perturbations removed to 1 µm)";
  // Eq. (5): the control forces of a physical trajectory vanish (to the simulation's tolerance).
  const auto forces = trajectory_residuals(physics, run.positions, run.initial_velocity);
  double force_scale = 0, worst_force = 0;
  for (const auto& f : forces)
    worst_force = std::max(worst_force, f.cwiseAbs().maxCoeff());
  const auto gravity = physics.dof_masses() * 9.81;
  force_scale = gravity.maxCoeff();
  EXPECT_LT(worst_force, 1e-6 * force_scale);
}

} // namespace
} // namespace elastolearn::learn
