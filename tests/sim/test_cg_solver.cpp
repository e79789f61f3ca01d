// The CG backend: it solves to the requested tolerance (against CHOLMOD), its float product
// steers CG as well as a double one (iteration count), and it is bit-identical for any thread
// count. Matrices: SystemMatrix patterns (whole-vertex triplets, fixed face dropped) of a box bar
// with ≥ 4 × 1024 free vertices, so the product runs in 4 column ranges (kMinRangeColumns in
// linear_solver.cpp), in lattice vertex order (spills reach into the previous range only) and in a
// random vertex order (spills reach into every earlier range).
#include <elastolearn/fem/system_matrix.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <gtest/gtest.h>
#include <numeric>
#include <random>
#include <tbb/task_arena.h>

using namespace elastolearn;

namespace {

/// A = Σ_e (L ⊗ S_e + B_eᵀB_e) + shift·I on the bar's pattern: L = 4I − 11ᵀ the tet's graph
/// Laplacian, S_e a random SPD 3×3 and B_e a random 3×12 (seeded by e). A stiffness-like SPD
/// matrix with λ_min ≥ shift whose off-diagonal 3×3 blocks are not symmetric (A_IJ = A_JIᵀ only).
/// `shuffle` renumbers the vertices randomly (a badly ordered mesh).
struct TestSystem {
  fem::SystemMatrix system;
  double shift = 0;
};

TestSystem make_system(bool shuffle, double shift) {
  const auto mesh = mesh::make_box_bar(Vec3(0.4, 0.1, 0.1), { 40, 10, 10 });
  std::vector<int> order(mesh.num_vertices());
  std::iota(order.begin(), order.end(), 0);
  if (shuffle)
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
  Tets tets = mesh.tets();
  for (int i = 0; i < tets.size(); ++i)
    tets.data()[i] = order[tets.data()[i]];
  std::vector<int> fixed = mesh::vertices_with_min_coordinate(mesh, 0, 1e-9);
  for (int& v : fixed)
    v = order[v];
  TestSystem s { fem::SystemMatrix(tets, fem::DofMap(mesh.num_vertices(), fixed)), shift };
  s.system.add_elements([](int e, Mat12& K) {
    std::minstd_rand rng(e + 1); // cheap to seed per element
    std::uniform_real_distribution<double> u(-1, 1);
    Mat3 C;
    Eigen::Matrix<double, 3, 12> B;
    for (int i = 0; i < 9; ++i)
      C.data()[i] = u(rng);
    for (int i = 0; i < 36; ++i)
      B.data()[i] = 0.2 * u(rng);
    const Mat3 S = C * C.transpose() + 0.5 * Mat3::Identity();
    K = B.transpose() * B;
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 4; ++c)
        K.block<3, 3>(3 * a, 3 * c) += (a == c ? 3.0 : -1.0) * S;
  });
  s.system.add_diagonal(VecX::Ones(s.system.size()), shift);
  return s;
}

VecX random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  VecX b(n);
  for (double& v : b)
    v = normal(rng);
  return b;
}

/// Upper bound on the condition number: Gershgorin for λ_max, the shift for λ_min.
double condition_bound(const TestSystem& s) {
  const auto& A = s.system.matrix();
  return (A.cwiseAbs() * VecX::Ones(A.rows())).maxCoeff() / s.shift;
}

} // namespace

class CgSolver : public ::testing::TestWithParam<bool> { };

TEST_P(CgSolver, MatchesTheDirectSolveToTheRequestedTolerance) {
  // One analysed CG solver for two matrices of the same pattern (factorize refreshes the values).
  const double tol = 1e-10;
  auto cg = sim::make_linear_solver(sim::LinearSolverType::ConjugateGradient);
  bool analyzed = false;
  for (double shift : { 1e-2, 1.0 }) {
    const TestSystem s = make_system(GetParam(), shift);
    const auto& A = s.system.matrix();
    if (!analyzed)
      cg->analyze(A), analyzed = true;
    ASSERT_TRUE(cg->factorize(A));
    const VecX b = random_vector(A.rows(), 1);
    VecX x;
    ASSERT_TRUE(cg->solve(b, x, tol));

    auto direct = sim::make_linear_solver(sim::LinearSolverType::Cholmod);
    direct->analyze(A);
    ASSERT_TRUE(direct->factorize(A));
    VecX reference;
    ASSERT_TRUE(direct->solve(b, reference, 0));

    // The contract, recomputed here: ‖b − Ax‖ ≤ tol‖b‖ (1 % slack for the residual's own
    // round-off, ~1e-16‖A‖‖x‖, next to tol‖b‖).
    EXPECT_LE((b - A * x).norm(), 1.01 * tol * b.norm());
    // Hence ‖x − x*‖ ≤ ‖r‖/λ_min ≤ κ·tol·‖x*‖ (κ ≤ 4e4 and 4e2 here, so with shift 1 a merely
    // float-accurate answer, ~1e-7, fails); CHOLMOD's own error, ~κ·1e-16, is far below.
    const double kappa = condition_bound(s);
    EXPECT_LE((x - reference).norm(), kappa * tol * reference.norm()) << "kappa bound " << kappa;
  }
}

TEST_P(CgSolver, FloatProductSteersAsWellAsADoubleOne) {
  // Iterations to 1e-6 (Newton's usual forcing range) within 5 % + 3 of Eigen's double
  // Jacobi-PCG from the same start: float rounding of A (~6e-8) barely perturbs the Krylov
  // recurrence (measured: 1 more of 59–79). A wrong float product converges to a wrong x,
  // fails the true-residual test and restarts, ending in the double product: many more.
  const double tol = 1e-6;
  for (double shift : { 1e-2, 1.0 }) {
    const TestSystem s = make_system(GetParam(), shift);
    const auto& A = s.system.matrix();
    auto cg = sim::make_linear_solver(sim::LinearSolverType::ConjugateGradient);
    cg->analyze(A);
    ASSERT_TRUE(cg->factorize(A));
    const VecX b = random_vector(A.rows(), 1);
    VecX x;
    ASSERT_TRUE(cg->solve(b, x, tol));
    Eigen::ConjugateGradient<fem::SparseMatrix, Eigen::Lower | Eigen::Upper,
        Eigen::DiagonalPreconditioner<double>>
        eigen_cg(A);
    eigen_cg.setTolerance(tol);
    const VecX eigen_x = eigen_cg.solve(b);
    ASSERT_EQ(eigen_cg.info(), Eigen::Success);
    EXPECT_LE(cg->last_iterations(), 1.05 * eigen_cg.iterations() + 3)
        << "Eigen's double CG: " << eigen_cg.iterations() << " iterations";
  }
}

TEST_P(CgSolver, BitIdenticalForAnyThreadCount) {
  // The product's column ranges are fixed by the pattern and their spills are added in range
  // order, so neither the thread count nor the schedule may change a single bit.
  const TestSystem s = make_system(GetParam(), 0.1);
  const auto& A = s.system.matrix();
  const VecX b = random_vector(A.rows(), 2);
  auto solve_with = [&](int threads) {
    VecX x;
    int iterations = 0;
    tbb::task_arena(threads).execute([&] {
      auto cg = sim::make_linear_solver(sim::LinearSolverType::ConjugateGradient);
      cg->analyze(A);
      EXPECT_TRUE(cg->factorize(A));
      EXPECT_TRUE(cg->solve(b, x, 1e-8));
      iterations = cg->last_iterations();
    });
    return std::pair(x, iterations);
  };
  const auto [x1, iterations1] = solve_with(1);
  ASSERT_GT(x1.norm(), 0);
  for (int threads : { 1, 2, 2 }) {
    const auto [x, iterations] = solve_with(threads);
    EXPECT_EQ(iterations, iterations1) << threads << " threads";
    EXPECT_TRUE(x == x1) << threads << " threads: max difference "
                         << (x - x1).cwiseAbs().maxCoeff();
  }
}

INSTANTIATE_TEST_SUITE_P(Sim, CgSolver, ::testing::Values(false, true),
    [](const auto& info) { return info.param ? "ShuffledVertices" : "LatticeOrder"; });
