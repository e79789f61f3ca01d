#include <elastolearn/learn/element_force_operator.hpp>

namespace elastolearn::learn {

Eigen::Matrix<double, 12, 3> element_force_operator(
    const fem::TetRestData& rest, const material::PrincipalFrame& frame) {
  // f_a = −vol U diag(p̂) Vᵀ g_a = Σ_k p̂_k (−vol (v_k · g_a) u_k).
  const Eigen::Matrix<double, 3, 4> vg = frame.V.transpose() * rest.gradients; // (v_k · g_a)
  Eigen::Matrix<double, 12, 3> G;
  for (int a = 0; a < 4; ++a)
    for (int k = 0; k < 3; ++k)
      G.block<3, 1>(3 * a, k) = (-rest.volume * vg(k, a)) * frame.U.col(k);
  return G;
}

Vec12 element_stiffness_damping_force(const fem::TetRestData& rest, const ElementState& state,
    const material::PrincipalTangent& tangent) {
  const Mat3 stress_rate
      = material::first_piola_differential(state.frame, tangent, state.deformation_rate);
  Vec12 f;
  Eigen::Map<Eigen::Matrix<double, 3, 4>>(f.data()).noalias()
      = -rest.volume * stress_rate * rest.gradients;
  return f;
}

Eigen::Matrix<double, 12, 12> element_stiffness_damping_operator(
    const fem::TetRestData& rest, const ElementState& state, material::DampingTangent kind) {
  // The exact eigen-form tangent is linear in (p̂, ∂p̂/∂σ), and so is the force: its columns are
  // the forces of the 12 unit inputs.
  Eigen::Matrix<double, 12, 12> op;
  for (int c = 0; c < 12; ++c) {
    Vec3 stress = Vec3::Zero();
    Mat3 derivative = Mat3::Zero();
    if (c < 3)
      stress[c] = 1;
    else
      derivative((c - 3) % 3, (c - 3) / 3) = 1;
    op.col(c) = element_stiffness_damping_force(
        rest, state, material::damping_tangent(state.frame, stress, derivative, kind));
  }
  return op;
}

} // namespace elastolearn::learn
