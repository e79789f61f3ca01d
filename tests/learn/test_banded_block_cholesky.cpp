// Banded block Cholesky: agrees with a dense solve on random SPD block-banded matrices of several
// sizes, stores only the band, and reports a matrix that is not positive definite.
#include <elastolearn/learn/banded_block_cholesky.hpp>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// A random SPD block-banded matrix shaped like Gauss–Newton normal equations JᵀJ + δI, where J
/// has a block row per step coupling z_{i−1}, z_i, z_{i+1} (so JᵀJ has block bandwidth 2).
BlockBandedMatrix random_normal_equations(int T, int r, unsigned seed, double shift = 1e-3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  BlockBandedMatrix a(T, r);
  for (int i = 0; i < T; ++i) {
    MatX J(r, 3 * r); // residual block of step i over (z_{i−1}, z_i, z_{i+1})
    for (Eigen::Index k = 0; k < J.size(); ++k)
      J.data()[k] = n(rng);
    for (int p = 0; p < 3; ++p) {
      const int bp = i - 1 + p;
      if (bp < 0 || bp >= T)
        continue;
      for (int q = 0; q <= p; ++q) {
        const int bq = i - 1 + q;
        if (bq < 0)
          continue;
        a.block(bp, bq) += J.middleCols(p * r, r).transpose() * J.middleCols(q * r, r);
      }
    }
  }
  for (int i = 0; i < T; ++i)
    a.block(i, i).diagonal().array() += shift;
  return a;
}

} // namespace

TEST(BlockBandedMatrix, MultiplyMatchesDense) {
  const BlockBandedMatrix a = random_normal_equations(7, 3, 1);
  const MatX dense = a.to_dense();
  EXPECT_LE((dense - dense.transpose()).norm(), 0.0); // exactly symmetric by construction
  const VecX x = VecX::LinSpaced(a.size(), -1, 2);
  EXPECT_LE((a.multiply(x) - dense * x).norm(), 1e-12 * (dense * x).norm());
  // Outside the band the dense matrix is zero: block (i+3, i) never appears.
  EXPECT_EQ(dense.block(9, 0, 3, 3).norm(), 0.0);
}

TEST(BandedBlockCholesky, MatchesDenseSolveOverSizes) {
  for (const int T : { 1, 2, 3, 5, 40 }) {
    for (const int r : { 1, 2, 6, 15 }) {
      const BlockBandedMatrix a = random_normal_equations(T, r, unsigned(100 * T + r));
      const MatX dense = a.to_dense();
      std::mt19937 rng(unsigned(T * r));
      std::normal_distribution<double> n(0.0, 1.0);
      VecX b(a.size());
      for (auto& v : b)
        v = n(rng);
      const Eigen::LLT<MatX> reference(dense);
      ASSERT_EQ(reference.info(), Eigen::Success);
      const VecX expected = reference.solve(b);
      const BandedBlockCholesky chol(a);
      const VecX x = chol.solve(b);
      // Both are backward-stable Cholesky solves of the same matrix: they agree to
      // ~ cond(A)·ε. The residual is the sharper check: ‖Ax − b‖ at round-off level.
      const double cond_estimate = 1e6; // δ = 1e-3 against entries of O(r)…O(10 r)
      EXPECT_LE((x - expected).norm(), cond_estimate * 1e-14 * expected.norm()) << T << " " << r;
      EXPECT_LE((dense * x - b).norm(), 1e-10 * b.norm()) << T << " " << r;
      EXPECT_NEAR(chol.log_determinant(), 2 * reference.matrixLLT().diagonal().array().log().sum(),
          1e-9 * std::max(1.0, std::abs(chol.log_determinant())));
    }
  }
}

TEST(BandedBlockCholesky, RefactorReusesAndSolvesInPlace) {
  BandedBlockCholesky chol;
  EXPECT_FALSE(chol.factored());
  for (unsigned seed : { 5u, 6u }) {
    const BlockBandedMatrix a = random_normal_equations(9, 4, seed);
    chol.compute(a);
    VecX b = VecX::Ones(a.size());
    chol.solve_in_place(b);
    EXPECT_LE((a.multiply(b) - VecX::Ones(a.size())).norm(), 1e-10 * std::sqrt(double(a.size())));
  }
}

TEST(BandedBlockCholesky, ReportsTheBlockThatIsNotPositiveDefinite) {
  BlockBandedMatrix a = random_normal_equations(6, 3, 2);
  a.block(4, 4).diagonal()[1] = -1e3; // breaks definiteness at block 4
  try {
    BandedBlockCholesky chol(a);
    FAIL() << "no error for an indefinite matrix";
  } catch (const NotPositiveDefiniteError& e) {
    EXPECT_EQ(e.block(), 4);
    EXPECT_NE(std::string(e.what()).find("pivot block 4"), std::string::npos) << e.what();
  }
  BlockBandedMatrix zero(3, 2); // singular
  EXPECT_THROW(BandedBlockCholesky { zero }, NotPositiveDefiniteError);
}
