// The fast one-sided Jacobi SVD behind principal_frame (svd3.hpp): reconstruction, orthogonality,
// sorting, the inversion sign convention, and agreement with Eigen's JacobiSVD on random,
// near-singular, graded, repeated and near-repeated inputs, plus degenerate and extreme ones.
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/svd3.hpp>

#include <support/material_states.hpp>

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// Every property of a PrincipalFrame of F. Backward stability of one-sided Jacobi: errors are a
/// few ε (2.2e-16) times ‖F‖, so 1e-14 (≈ 45 ε) relative leaves room for 3×3 products of rounding.
void expect_valid_frame(const Mat3& F, const PrincipalFrame& f) {
  const double tol = 1e-14;
  EXPECT_LE((f.U * f.stretches.asDiagonal() * f.V.transpose() - F).norm(), tol * F.norm());
  EXPECT_LE((f.U.transpose() * f.U - Mat3::Identity()).norm(), tol);
  EXPECT_LE((f.V.transpose() * f.V - Mat3::Identity()).norm(), tol);
  EXPECT_NEAR(f.U.determinant(), 1.0, tol);
  EXPECT_NEAR(f.V.determinant(), 1.0, tol);
  EXPECT_GE(f.stretches[0], f.stretches[1]);
  EXPECT_GE(f.stretches[1], std::abs(f.stretches[2]));
  EXPECT_GE(f.stretches[1], 0.0);
  // The sign of σ₂ is that of det F wherever det F is resolvable at this precision.
  const double det = F.determinant();
  const double det_tol = 1e-13 * std::pow(F.norm(), 3);
  if (det > det_tol) {
    EXPECT_GT(f.stretches[2], 0.0);
  }
  if (det < -det_tol) {
    EXPECT_LT(f.stretches[2], 0.0);
  }
}

/// Singular values agree with Eigen's JacobiSVD to a few ε of σ_max (both are backward stable).
void expect_matches_jacobi(const Mat3& F, const PrincipalFrame& f) {
  const Vec3 reference = Eigen::JacobiSVD<Mat3>(F).singularValues();
  EXPECT_LE((f.stretches.cwiseAbs() - reference).cwiseAbs().maxCoeff(), 1e-14 * reference[0]);
}

Mat3 random_matrix(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Mat3 F;
  for (int k = 0; k < 9; ++k)
    F.data()[k] = u(rng);
  return F;
}

} // namespace

TEST(Svd3, RandomMatricesAreDecomposedAccurately) {
  std::mt19937 rng(11);
  int max_sweeps = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Mat3 F = random_matrix(rng);
    Svd3Info info;
    const PrincipalFrame f = svd3(F, &info);
    SCOPED_TRACE(trial);
    expect_valid_frame(F, f);
    expect_matches_jacobi(F, f);
    EXPECT_FALSE(info.fallback);
    max_sweeps = std::max(max_sweeps, info.sweeps);
  }
  // Quadratic convergence: a handful of sweeps, far from the cap where JacobiSVD takes over.
  EXPECT_LE(max_sweeps, 7);
}

TEST(Svd3, NearRotationsConvergeInFewSweeps) {
  // The simulator's common case, F = R (I + small strain).
  std::mt19937 rng(12);
  for (int trial = 0; trial < 500; ++trial) {
    const Mat3 F = random_rotation(rng) * (Mat3::Identity() + 0.05 * random_matrix(rng));
    Svd3Info info;
    expect_valid_frame(F, svd3(F, &info));
    EXPECT_LE(info.sweeps, 5);
  }
}

TEST(Svd3, RepeatedAndNearRepeatedSingularValues) {
  std::mt19937 rng(13);
  const double gaps[] = { 0.0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3 };
  for (double gap : gaps) {
    for (const Vec3& s :
        { Vec3(1 + gap, 1, 0.5), Vec3(1, 0.5 + gap, 0.5), Vec3(1 + 2 * gap, 1 + gap, 1),
            Vec3(1 + gap, 1, -1), Vec3(2, 1 + gap, -1), Vec3(1 + gap, 1, 0) }) {
      for (int trial = 0; trial < 20; ++trial) {
        const Mat3 F = random_rotation(rng) * s.asDiagonal() * random_rotation(rng).transpose();
        SCOPED_TRACE(::testing::Message() << "gap " << gap << " s " << s.transpose());
        Svd3Info info;
        const PrincipalFrame f = svd3(F, &info);
        expect_valid_frame(F, f);
        expect_matches_jacobi(F, f);
        EXPECT_FALSE(info.fallback);
        // The signed stretches themselves (σ₂ carries det F's sign), to rounding of F.
        EXPECT_LE((f.stretches - s).cwiseAbs().maxCoeff(), 1e-14 * s.cwiseAbs().maxCoeff());
      }
    }
  }
}

TEST(Svd3, NearSingularMatrices) {
  std::mt19937 rng(14);
  for (double small : { 1e-3, 1e-6, 1e-9, 1e-12, 1e-15, 1e-20, 0.0 }) {
    for (const Vec3& s : { Vec3(1, 0.7, small), Vec3(1, small, small), Vec3(1, small, 0.0),
             Vec3(1, 0.7, -small), Vec3(1, small, -small) }) {
      for (int trial = 0; trial < 10; ++trial) {
        const Mat3 F = random_rotation(rng) * s.asDiagonal() * random_rotation(rng).transpose();
        SCOPED_TRACE(::testing::Message() << "s " << s.transpose());
        const PrincipalFrame f = svd3(F);
        expect_valid_frame(F, f);
        expect_matches_jacobi(F, f);
      }
    }
  }
}

TEST(Svd3, GradedColumnsKeepRelativeAccuracyOfTinySingularValues) {
  // F = R D with D diagonal: the singular values are D's entries exactly, and one-sided Jacobi
  // computes each to a few ε *relative* to itself (Demmel & Veselić), not only to σ_max.
  std::mt19937 rng(15);
  const Vec3 d(1.0, 1e-8, 1e-15);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 F = random_rotation(rng) * d.asDiagonal();
    const PrincipalFrame f = svd3(F);
    expect_valid_frame(F, f);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(f.stretches[k], d[k], 1e-13 * d[k]) << k;
  }
}

TEST(Svd3, DegenerateAndSpecialMatrices) {
  Mat3 permutation;
  permutation << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  Mat3 odd_permutation;
  odd_permutation << 0, 1, 0, 1, 0, 0, 0, 0, 1;
  Mat3 rank_one = Vec3(1, 2, 3) * Vec3(-1, 0.5, 2).transpose();
  Mat3 rank_two = rank_one + Vec3(0, 1, -1) * Vec3(1, 1, 1).transpose();
  Mat3 single_entry = Mat3::Zero();
  single_entry(2, 1) = -3;
  for (const Mat3& F : { Mat3(Mat3::Identity()), Mat3(-Mat3::Identity()), permutation,
           odd_permutation, rank_one, rank_two, single_entry, Mat3(Vec3(3, -2, 1).asDiagonal()),
           Mat3(Vec3(-1, -1, 1).asDiagonal()), Mat3(Mat3::Constant(1.0)) }) {
    SCOPED_TRACE(::testing::Message() << "F\n" << F);
    const PrincipalFrame f = svd3(F);
    expect_valid_frame(F, f);
    expect_matches_jacobi(F, f);
  }
  const PrincipalFrame zero = svd3(Mat3::Zero());
  EXPECT_EQ(zero.stretches, Vec3::Zero());
  EXPECT_EQ(zero.U, Mat3::Identity());
  EXPECT_EQ(zero.V, Mat3::Identity());
  // A reflection through one axis: stretches (1, 1, −1).
  EXPECT_LE((svd3(Mat3(Vec3(1, -1, 1).asDiagonal())).stretches - Vec3(1, 1, -1)).norm(), 1e-15);
}

TEST(Svd3, ExtremeMagnitudesAreScaledExactly) {
  std::mt19937 rng(16);
  const Vec3 s(1.3, 0.9, -0.4);
  const Mat3 F = random_rotation(rng) * s.asDiagonal() * random_rotation(rng).transpose();
  const PrincipalFrame unit = svd3(F);
  for (double factor : { 0x1p-900, 0x1p-300, 0x1p300, 0x1p900 }) {
    // Power-of-two factors scale F exactly, so the frame must scale exactly too.
    const PrincipalFrame f = svd3(factor * F);
    expect_valid_frame(factor * F, f);
    EXPECT_EQ(f.stretches, factor * unit.stretches) << factor;
    EXPECT_EQ(f.U, unit.U);
    EXPECT_EQ(f.V, unit.V);
  }
  // Denormal entries.
  const Mat3 tiny = 1e-310 * Mat3(Vec3(2, 1, -0.5).asDiagonal());
  const PrincipalFrame f = svd3(tiny);
  EXPECT_NEAR(f.stretches[0], 2e-310, 1e-322);
  EXPECT_LT(f.stretches[2], 0.0);
}

TEST(Svd3, NonFiniteInputGivesNaN) {
  Mat3 F = Mat3::Identity();
  F(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(svd3(F).stretches.array().isNaN().all());
  F(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(svd3(F).stretches.array().isNaN().all());
}

TEST(Svd3, SingularVectorsMatchJacobiForDistinctValues) {
  // Where singular values are well separated the singular vectors are unique up to sign.
  std::mt19937 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    const Mat3 F = random_rotation(rng) * Vec3(2.0, 1.0, 0.4).asDiagonal()
        * random_rotation(rng).transpose();
    const Eigen::JacobiSVD<Mat3> ref(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const PrincipalFrame f = svd3(F);
    for (int k = 0; k < 3; ++k) {
      // Vector error ≤ ε‖F‖ / gap ≈ 1e-15: 1e-13 is loose yet catches any mix-up.
      EXPECT_NEAR(std::abs(f.U.col(k).dot(ref.matrixU().col(k))), 1.0, 1e-13);
      EXPECT_NEAR(std::abs(f.V.col(k).dot(ref.matrixV().col(k))), 1.0, 1e-13);
    }
  }
}

TEST(Svd3, PrincipalFrameIsSvd3) {
  for (const auto& state : material_states()) {
    const PrincipalFrame a = principal_frame(state.F), b = svd3(state.F);
    EXPECT_EQ(a.U, b.U) << state.name;
    EXPECT_EQ(a.V, b.V) << state.name;
    EXPECT_EQ(a.stretches, b.stretches) << state.name;
  }
}
