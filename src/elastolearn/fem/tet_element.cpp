#include <elastolearn/fem/tet_element.hpp>

#include <Eigen/LU>

namespace elastolearn::fem {

std::vector<TetRestData> precompute_rest_data(const mesh::TetMesh& mesh) {
  const auto& X = mesh.rest_positions();
  const auto& T = mesh.tets();
  std::vector<TetRestData> out(mesh.num_tets());
  for (int e = 0; e < mesh.num_tets(); ++e) {
    Mat3 Dm;
    for (int c = 0; c < 3; ++c)
      Dm.col(c) = (X.row(T(e, c + 1)) - X.row(T(e, 0))).transpose();
    const Mat3 Dm_inv = Dm.inverse(); // TetMesh guarantees non-degenerate, positive tets
    out[e].volume = Dm.determinant() / 6.0;
    out[e].gradients.rightCols<3>() = Dm_inv.transpose();
    out[e].gradients.col(0) = -Dm_inv.transpose().rowwise().sum();
  }
  return out;
}

Mat12 element_matrix_from_tangent(const Mat9& H, const TetRestData& rest, bool symmetric) {
  const auto& g = rest.gradients;
  // W = H B: column (3b + k) of B has g_b[l] at row (k + 3l).
  Eigen::Matrix<double, 9, 12> W;
  for (int b = 0; b < 4; ++b)
    for (int k = 0; k < 3; ++k)
      W.col(3 * b + k) = H.col(k) * g(0, b) + H.col(k + 3) * g(1, b) + H.col(k + 6) * g(2, b);
  // K = Bᵀ W: row (3a + i) = Σ_j g_a[j] W.row(i + 3j). For symmetric H only the upper triangle
  // is computed and mirrored.
  Mat12 K;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      const int row = 3 * a + i;
      for (int col = symmetric ? row : 0; col < 12; ++col)
        K(row, col) = rest.volume
            * (g(0, a) * W(i, col) + g(1, a) * W(i + 3, col) + g(2, a) * W(i + 6, col));
    }
  if (symmetric)
    K.triangularView<Eigen::StrictlyLower>() = K.transpose();
  return K;
}

Mat12 element_stiffness(const material::PrincipalFrame& frame, const material::PrincipalTangent& t,
    const TetRestData& rest, double scale) {
  const double s = scale * rest.volume;
  const Eigen::Matrix<double, 3, 4> g = frame.V.transpose() * rest.gradients; // ĝ_a, rotated
  // A: the block term; D: the diagonal entries' weights (A_ii on the diagonal, a_il off it);
  // B: the transposed-entry weights b_ij (zero diagonal). All symmetric except A, D if the block is
  // not.
  const Mat3 A = s * t.block;
  Mat3 D = A, B = Mat3::Zero();
  static constexpr int pairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };
  for (int m = 0; m < 3; ++m) {
    const int i = pairs[m][0], j = pairs[m][1];
    D(i, j) = D(j, i) = 0.5 * s * (t.twist[m] + t.flip[m]);
    B(i, j) = B(j, i) = 0.5 * s * (t.twist[m] - t.flip[m]);
  }
  const bool symmetric = t.block == t.block.transpose();
  const Mat3& U = frame.U;
  Mat12 K;
  for (int b = 0; b < 4; ++b)
    for (int a = 0; a < (symmetric ? b + 1 : 4); ++a) {
      const Mat3 O = g.col(a) * g.col(b).transpose(); // O(i, j) = ĝ_a[i] ĝ_b[j]
      Mat3 local = O.cwiseProduct(A) + O.transpose().cwiseProduct(B);
      local.diagonal() = D * O.diagonal();
      K.block<3, 3>(3 * a, 3 * b).noalias() = U * local * U.transpose();
    }
  // Mirror the upper triangle (also within the diagonal blocks, which rounding leaves slightly
  // non-symmetric).
  if (symmetric)
    K.triangularView<Eigen::StrictlyLower>() = K.transpose();
  return K;
}

} // namespace elastolearn::fem
