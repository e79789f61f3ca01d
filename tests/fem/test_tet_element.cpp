// Element matrices of a linear tet: element_stiffness (straight from the eigen-form tangent)
// against vol·Bᵀ(dP/dF)B assembled from first_piola_derivative and element_matrix_from_tangent,
// for random frames and tangents (projected and not, symmetric and non-symmetric blocks,
// inverted states), and element_matrix_from_tangent against a dense Bᵀ H B.
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <support/material_states.hpp>

#include <gtest/gtest.h>
#include <random>

using namespace elastolearn;

namespace {

/// A random, non-degenerate tet's rest data (vertex 0 at the origin, volume > 0).
fem::TetRestData random_rest(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Mat3 Dm;
  do {
    for (int k = 0; k < 9; ++k)
      Dm.data()[k] = 0.1 * u(rng);
  } while (Dm.determinant() < 1e-5);
  fem::TetRestData rest;
  rest.volume = Dm.determinant() / 6.0;
  const Mat3 inv_t = Dm.inverse().transpose();
  rest.gradients.rightCols<3>() = inv_t;
  rest.gradients.col(0) = -inv_t.rowwise().sum();
  return rest;
}

/// B = ∂vec(F)/∂x_e (9×12), column-major vec(F), x_e = (x0, y0, z0, x1, …).
Eigen::Matrix<double, 9, 12> dense_b(const fem::TetRestData& rest) {
  Eigen::Matrix<double, 9, 12> B = Eigen::Matrix<double, 9, 12>::Zero();
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < 3; ++l)
        B(i + 3 * l, 3 * a + i) = rest.gradients(l, a);
  return B;
}

/// Both compute the same sums of products of O(‖K‖) terms in different orders: a few ε
/// relative to the largest entry; 1e-12 leaves margin and catches any index or sign slip.
void expect_close(const Mat12& fast, const Mat12& reference) {
  const double scale = reference.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LE((fast - reference).cwiseAbs().maxCoeff(), 1e-12 * scale);
}

} // namespace

TEST(ElementMatrixFromTangent, MatchesDenseProduct) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const fem::TetRestData rest = random_rest(rng);
    Mat9 H;
    for (int k = 0; k < 81; ++k)
      H.data()[k] = u(rng);
    const auto B = dense_b(rest);
    expect_close(fem::element_matrix_from_tangent(H, rest), rest.volume * B.transpose() * H * B);
    const Mat9 S = H + H.transpose();
    expect_close(
        fem::element_matrix_from_tangent(S, rest, true), rest.volume * B.transpose() * S * B);
  }
}

TEST(ElementStiffness, EqualsElementMatrixOfFirstPiolaDerivative) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    SCOPED_TRACE(trial);
    const fem::TetRestData rest = random_rest(rng);
    // Every fourth state inverted (σ₂ < 0); some with nearly equal stretches (stable limits).
    Vec3 s(1 + 0.5 * u(rng), 1 + 0.5 * u(rng), 1 + 0.5 * u(rng));
    if (trial % 4 == 0)
      s[2] = -0.3 * std::abs(u(rng));
    if (trial % 5 == 0)
      s[1] = s[0] + 1e-8;
    const material::PrincipalFrame frame = material::principal_frame(
        test::random_rotation(rng) * s.asDiagonal() * test::random_rotation(rng).transpose());
    const Vec3 P(u(rng), u(rng), u(rng));
    Mat3 dP;
    for (int k = 0; k < 9; ++k)
      dP.data()[k] = u(rng);
    if (trial % 2 == 0)
      dP = dP * dP.transpose(); // symmetric block, as hyperelastic models give
    const double scale = 1 + u(rng);
    for (bool project : { false, true }) {
      SCOPED_TRACE(project ? "projected" : "exact");
      const auto tangent = material::principal_tangent(frame, P, dP, project);
      const Mat9 H = scale * material::first_piola_derivative(frame, tangent);
      expect_close(fem::element_stiffness(frame, tangent, rest, scale),
          fem::element_matrix_from_tangent(H, rest, false));
    }
  }
}

TEST(ElementStiffness, SymmetricForSymmetricBlockOnly) {
  std::mt19937 rng(3);
  const fem::TetRestData rest = random_rest(rng);
  const auto frame = material::principal_frame(test::rotated_stretch(Vec3(1.2, 0.9, -0.4), 4));
  Mat3 block;
  block << 2, 0.3, 0.1, 0.3, 1, -0.2, 0.1, -0.2, 0.5;
  const material::PrincipalTangent symmetric { block, Vec3(1, 0.5, 0.2), Vec3(0.8, -0.3, 0.4) };
  const Mat12 K = fem::element_stiffness(frame, symmetric, rest);
  EXPECT_EQ(K, K.transpose()); // mirrored exactly
  material::PrincipalTangent skew = symmetric;
  skew.block(0, 1) += 0.5;
  const Mat12 Ks = fem::element_stiffness(frame, skew, rest);
  EXPECT_GT((Ks - Ks.transpose()).cwiseAbs().maxCoeff(), 1e-3 * Ks.cwiseAbs().maxCoeff());
}
