// Inversion-safe SVD, stretch rates and the world-frame stress of principal_stress.hpp.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <support/material_states.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

std::vector<MaterialState> svd_states() {
  auto states = material_states();
  states.push_back({ "reflection", Vec3(1, 1, -1).asDiagonal().toDenseMatrix() });
  states.push_back({ "singular", rotated_stretch(Vec3(1.2, 0.7, 0.0), 41) });
  states.push_back({ "rank_one", rotated_stretch(Vec3(1.5, 0.0, 0.0), 42) });
  states.push_back({ "zero", Mat3::Zero() });
  states.push_back({ "inverted_all_equal", rotated_stretch(Vec3(0.9, 0.9, -0.9), 43) });
  states.push_back({ "point_reflection", -Mat3::Identity() });
  return states;
}

} // namespace

TEST(PrincipalFrame, ReconstructsFWithProperRotationsAndSortedStretches) {
  for (const auto& state : svd_states()) {
    SCOPED_TRACE(state.name);
    const PrincipalFrame f = principal_frame(state.F);
    // Jacobi SVD is backward stable: errors of a few ulps of ‖F‖.
    const double tol = 1e-14 * std::max(1.0, state.F.norm());
    EXPECT_LE((f.U * f.stretches.asDiagonal() * f.V.transpose() - state.F).norm(), tol);
    EXPECT_LE((f.U.transpose() * f.U - Mat3::Identity()).norm(), 1e-14);
    EXPECT_LE((f.V.transpose() * f.V - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(f.U.determinant(), 1.0, 1e-14);
    EXPECT_NEAR(f.V.determinant(), 1.0, 1e-14);
    EXPECT_GE(f.stretches[0], f.stretches[1]);
    EXPECT_GE(f.stretches[1], f.stretches[2]);
    EXPECT_GE(f.stretches[1], 0.0);
    // Only the smallest stretch may be negative, and only for an inverted F.
    EXPECT_GE(f.stretches[1], std::abs(f.stretches[2]));
    const double det = state.F.determinant();
    if (det < -1e-12) {
      EXPECT_LT(f.stretches[2], 0.0);
    }
    if (det > 1e-12) {
      EXPECT_GT(f.stretches[2], 0.0);
    }
  }
}

TEST(PrincipalFrame, InvertedStretchesAreRecovered) {
  const Vec3 s(1.15, 0.8, -0.3);
  const PrincipalFrame f = principal_frame(rotated_stretch(s, 6));
  EXPECT_LE((f.stretches - s).norm(), 1e-14);
  const PrincipalFrame g = principal_frame(-Mat3::Identity());
  EXPECT_LE((g.stretches - Vec3(1, 1, -1)).norm(), 1e-14);
}

TEST(PrincipalFrame, StretchRatesAreDiagonalOfRotatedRate) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& state : material_states()) {
    const PrincipalFrame f = principal_frame(state.F);
    Mat3 Fdot;
    for (int k = 0; k < 9; ++k)
      Fdot.data()[k] = u(rng);
    const Mat3 rotated = f.U.transpose() * Fdot * f.V;
    EXPECT_LE((stretch_rates(f, Fdot) - rotated.diagonal()).norm(), 1e-14 * Fdot.norm())
        << state.name;
    // A rate along the principal directions, Ḟ = U diag(r) Vᵀ, is recovered exactly.
    const Vec3 r(0.3, -0.2, 0.5);
    EXPECT_LE((stretch_rates(f, f.U * r.asDiagonal() * f.V.transpose()) - r).norm(), 1e-14);
  }
}

TEST(PrincipalFrame, FirstPiolaRotatesTheDiagonalStress) {
  const PrincipalFrame f = principal_frame(rotated_stretch(Vec3(1.3, 0.9, 0.75), 2));
  const Vec3 p(3.0, -1.0, 2.0);
  const Mat3 P = first_piola(f, p);
  EXPECT_LE((f.U.transpose() * P * f.V - Mat3(p.asDiagonal())).norm(), 1e-14 * p.norm());
}

TEST(FirstPiolaDerivative, UsesColumnMajorVecOnBothSides) {
  // For P̂ = σ (P = F), dP/dF is the identity; the cubic case below checks the index layout.
  const PrincipalFrame f = principal_frame(Vec3(1.5, 1.2, 0.8).asDiagonal().toDenseMatrix());
  const Mat9 id = first_piola_derivative(f, f.stretches, Mat3::Identity(), false);
  EXPECT_LE((id - Mat9::Identity()).norm(), 1e-14);
  // P̂ᵢ = σᵢ³ (Ψ = Σσᵢ⁴/4) at diagonal F: ∂P(0,1)/∂F(0,1) = (σ0⁴ − σ1⁴)/(σ0² − σ1²) = σ0² + σ1².
  const Vec3 s = f.stretches;
  const Mat9 cubic = first_piola_derivative(
      f, s.array().cube(), Mat3((3 * s.array().square()).matrix().asDiagonal()), false);
  const int i01 = 0 + 3 * 1; // vec index of entry (0, 1)
  EXPECT_NEAR(cubic(i01, i01), s[0] * s[0] + s[1] * s[1], 1e-13);
  EXPECT_NEAR(cubic(0, 0), 3 * s[0] * s[0], 1e-13);
}

TEST(DampingTangent, IsTheExactTangentWithoutItsFlipPart) {
  // Rayleigh damping's stiffness (fem::ElasticForce): exact block and twist, no flip, and no
  // projection, so that it is linear in the stress (the stress reconstruction relies on that).
  const PrincipalFrame frame = principal_frame(rotated_stretch(Vec3(1.2, 0.9, 0.75), 7));
  const Vec3 p1(3e3, -1e3, -4e3), p2(-2e3, 5e2, 1e3);
  Mat3 d1, d2;
  d1 << 5e4, 1e4, -2e4, 3e3, 4e4, 1e4, -1e4, 2e4, 6e4; // not symmetric (as an RBF's ∂N/∂σ)
  d2 << -3e4, 2e3, 1e3, 5e3, -2e4, 0, 1e3, 4e3, -1e4;
  const PrincipalTangent exact = principal_tangent(frame, p1, d1, false);
  const PrincipalTangent t1 = damping_tangent(frame, p1, d1, DampingTangent::FlipFree);
  EXPECT_EQ(t1.block, exact.block);
  EXPECT_EQ(t1.twist, exact.twist);
  EXPECT_EQ(t1.flip, Vec3::Zero());
  // Linear: T(a p1 + b p2) = a T(p1) + b T(p2), including the negative (unprojected) parts.
  const PrincipalTangent t2 = damping_tangent(frame, p2, d2, DampingTangent::FlipFree);
  const PrincipalTangent sum
      = damping_tangent(frame, 2 * p1 - 3 * p2, 2 * d1 - 3 * d2, DampingTangent::FlipFree);
  EXPECT_LE((sum.block - (2 * t1.block - 3 * t2.block)).norm(), 1e-9 * sum.block.norm());
  EXPECT_LE((sum.twist - (2 * t1.twist - 3 * t2.twist)).norm(), 1e-9 * sum.twist.norm());
  EXPECT_LT(t2.block.minCoeff(), 0.0); // the test does exercise an indefinite tangent
}

TEST(DampingTangent, ExactIsTheFullUnprojectedTangent) {
  const PrincipalFrame frame = principal_frame(rotated_stretch(Vec3(1.2, 0.9, 0.75), 7));
  const Vec3 p(3e3, -1e3, -4e3);
  Mat3 d;
  d << 5e4, 1e4, -2e4, 3e3, 4e4, 1e4, -1e4, 2e4, 6e4;
  const PrincipalTangent exact = principal_tangent(frame, p, d, false);
  const PrincipalTangent t = damping_tangent(frame, p, d, DampingTangent::Exact);
  EXPECT_EQ(t.block, exact.block);
  EXPECT_EQ(t.twist, exact.twist);
  EXPECT_EQ(t.flip, exact.flip);
  EXPECT_NE(t.flip, Vec3::Zero());
}

TEST(DampingTangent, NamesRoundTripAndUnknownNamesAreRefused) {
  for (DampingTangent t : all_damping_tangents)
    EXPECT_EQ(damping_tangent_from_string(to_string(t)), t);
  try {
    damping_tangent_from_string("projected", "s.json: material.damping.tangent");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("s.json: material.damping.tangent"), std::string::npos) << what;
    EXPECT_NE(what.find("flip-free, exact"), std::string::npos) << what;
  }
}
