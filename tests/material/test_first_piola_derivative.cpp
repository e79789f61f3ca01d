// The structured dP/dF of principal_stress.cpp (H = Y Mᵀ from rank-one terms, upper triangle
// mirrored when projected, eigensolver skipped for a positive-definite ∂P̂/∂σ) against the
// textbook formula kron(V, U) K kron(V, U)ᵀ with a dense 9×9 K, for every model and test state,
// projected and exact, and for a non-symmetric ∂P̂/∂σ (as a correction term can produce).
#include "model_zoo.hpp"

#include <elastolearn/material/principal_stress.hpp>

#include <support/material_states.hpp>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// Reference: the principal-frame tangent K as a dense 9×9 (the 3×3 block on the diagonal vec
/// entries, one 2×2 twist/flip block per pair), rotated by W = kron(V, U). Same stable limits
/// and the same projection (always through the eigensolver) as the documented contract.
Mat9 reference_derivative(const PrincipalFrame& f, const Vec3& P, const Mat3& dP, bool project) {
  constexpr double gap = 1e-5;
  const Vec3& s = f.stretches;
  Mat3 A = dP;
  if (project) {
    const Mat3 S = 0.5 * (dP + dP.transpose());
    Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
    A = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal()
        * eig.eigenvectors().transpose();
  }
  Mat9 K = Mat9::Zero();
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      K(4 * i, 4 * j) = A(i, j);
  for (const auto& [i, j] : { std::pair { 0, 1 }, std::pair { 0, 2 }, std::pair { 1, 2 } }) {
    const double scale = std::max({ 1.0, std::abs(s[i]), std::abs(s[j]) });
    double twist = std::abs(s[i] - s[j]) > gap * scale
        ? (P[i] - P[j]) / (s[i] - s[j])
        : 0.5 * ((dP(i, i) - dP(i, j)) + (dP(j, j) - dP(j, i)));
    double sum = s[i] + s[j];
    if (std::abs(sum) < gap * scale)
      sum = std::copysign(gap * scale, sum);
    double flip = (P[i] + P[j]) / sum;
    if (project) {
      twist = std::max(twist, 0.0);
      flip = std::max(flip, 0.0);
    }
    const int p = i + 3 * j, q = j + 3 * i;
    K(p, p) = K(q, q) = 0.5 * (twist + flip);
    K(p, q) = K(q, p) = 0.5 * (twist - flip);
  }
  Mat9 W;
  for (int l = 0; l < 3; ++l)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          W(i + 3 * j, k + 3 * l) = f.U(i, k) * f.V(j, l);
  return W * K * W.transpose();
}

/// Both are exact rearrangements of one formula: they differ by rounding of sums of at most 9
/// products of O(‖H‖) terms, a few ε relative; 1e-13 leaves margin and catches any index slip.
void expect_same(const Mat9& fast, const Mat9& reference) {
  const double scale = std::max(reference.cwiseAbs().maxCoeff(), 1e-300);
  EXPECT_LE((fast - reference).cwiseAbs().maxCoeff(), 1e-13 * scale);
}

template <typename Factory> class FirstPiolaDerivativeStructure : public ::testing::Test {
  protected:
  std::unique_ptr<ElasticModel> model = Factory::make();
};
TYPED_TEST_SUITE(FirstPiolaDerivativeStructure, AllModelFactories);

} // namespace

TYPED_TEST(FirstPiolaDerivativeStructure, MatchesDenseKroneckerFormula) {
  const ElasticModel& m = *this->model;
  auto states = material_states();
  states.push_back({ "compressed", rotated_stretch(Vec3(0.8, 0.78, 0.76), 31) });
  for (const auto& state : states) {
    SCOPED_TRACE(state.name);
    const PrincipalFrame f = principal_frame(state.F);
    const Vec3 P = m.principal_stress(f.stretches);
    const Mat3 dP = m.principal_stress_derivative(f.stretches);
    for (bool project : { false, true }) {
      SCOPED_TRACE(project ? "projected" : "exact");
      expect_same(
          first_piola_derivative(f, P, dP, project), reference_derivative(f, P, dP, project));
    }
  }
}

TEST(FirstPiolaDerivativeGeneral, NonSymmetricAndIndefiniteStressDerivatives) {
  // Random P̂ and ∂P̂/∂σ (non-symmetric, often indefinite) exercise the general product and the
  // eigensolver branch of the projection.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Mat3 F, dP;
    for (int k = 0; k < 9; ++k) {
      F.data()[k] = u(rng);
      dP.data()[k] = u(rng);
    }
    const Vec3 P(u(rng), u(rng), u(rng));
    const PrincipalFrame f = principal_frame(F);
    for (bool project : { false, true })
      expect_same(
          first_piola_derivative(f, P, dP, project), reference_derivative(f, P, dP, project));
  }
}

TEST(FirstPiolaDerivativeGeneral, PositiveDefiniteShortcutEqualsProjection) {
  // A positive-definite symmetric ∂P̂/∂σ is left as it is by the projection; one with a zero or
  // negative eigenvalue goes through the eigensolver. Both must match the reference.
  const PrincipalFrame f = principal_frame(rotated_stretch(Vec3(1.3, 0.9, 0.75), 2));
  const Vec3 P(0.4, -0.1, 0.2);
  Mat3 spd;
  spd << 2, 0.5, 0.1, 0.5, 1, 0.2, 0.1, 0.2, 0.5;
  Mat3 semidefinite = Vec3(1, 2, 3) * Vec3(1, 2, 3).transpose();
  Mat3 indefinite;
  indefinite << 1, 2, 0, 2, 1, 0, 0, 0, 1;
  for (const Mat3& dP : { spd, semidefinite, indefinite })
    expect_same(first_piola_derivative(f, P, dP, true), reference_derivative(f, P, dP, true));
}
