#pragma once
/// \file Per-tet rest-state precomputation for linear tetrahedra (paper 000 §4.1, "B_m").
#include <elastolearn/core/types.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <vector>

namespace elastolearn::fem {

/// Rest data of one linear tet: volume and the gradients of its four shape functions.
/// F = Σ_a x_a g_aᵀ = Ds Dm⁻¹, so g_1..g_3 are the rows of Dm⁻¹ and g_0 = −(g_1 + g_2 + g_3).
struct TetRestData {
  double volume = 0; ///< rest volume [m³]
  Eigen::Matrix<double, 3, 4> gradients; ///< column a = ∂N_a/∂X [1/m]
};

/// Precompute the rest data of every tet (once per mesh).
std::vector<TetRestData> precompute_rest_data(const mesh::TetMesh& mesh);

/// Gather the 4 vertex 3-vectors of tet `tet` from a flat 3n vector into a 3×4 matrix.
inline Eigen::Matrix<double, 3, 4> gather_tet(const VecX& flat, const Eigen::Vector4i& tet) {
  Eigen::Matrix<double, 3, 4> out;
  for (int a = 0; a < 4; ++a)
    out.col(a) = flat.segment<3>(3 * tet[a]);
  return out;
}

/// F = Σ_a x_a g_aᵀ for vertex positions (or velocities, giving Ḟ) as columns of `x`.
inline Mat3 deformation_gradient(const Eigen::Matrix<double, 3, 4>& x, const TetRestData& rest) {
  return x * rest.gradients.transpose();
}

/// Element 12×12 matrix vol · Bᵀ H B with B = ∂vec(F)/∂x_e (column-major vec(F); x_e ordered
/// x0,y0,z0,x1,...). Exploits B's Kronecker structure: ~750 multiply-adds instead of ~2300, and
/// with `symmetric` (H symmetric, e.g. a projected tangent) computes only the upper triangle.
Mat12 element_matrix_from_tangent(const Mat9& H, const TetRestData& rest, bool symmetric = false);

/// Element stiffness scale · vol · Bᵀ (dP/dF) B straight from the eigen-form tangent, without
/// the 9×9 (equal to element_matrix_from_tangent(scale · first_piola_derivative(frame, tangent))
/// to rounding). With ĝ_a = Vᵀ g_a, a_ij = ½(twist + flip), b_ij = ½(twist − flip) per pair and
/// A = tangent.block, the 3×3 block of vertices a, b is K_ab = U K̂_ab Uᵀ with
///   K̂_ab(i, j) = vol [ĝ_a[i] A_ij ĝ_b[j] + δ_ij Σ_{l≠i} a_il ĝ_a[l] ĝ_b[l] + (1 − δ_ij) b_ij
///   ĝ_a[j] ĝ_b[i]]
/// (from dP = U dP̂ Vᵀ, dF̂ = Uᵀ dx_b ĝ_bᵀ, f_a = −vol P g_a). A symmetric block gives a symmetric
/// K, of which only the 10 upper vertex blocks are computed; otherwise all 16 are.
Mat12 element_stiffness(const material::PrincipalFrame& frame,
    const material::PrincipalTangent& tangent, const TetRestData& rest, double scale = 1.0);

} // namespace elastolearn::fem
