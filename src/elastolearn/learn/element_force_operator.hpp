#pragma once
/// \file The element operators of stress reconstruction (paper 000 §4.1, §6.1): the nodal forces
/// of a principal stress in one element (one block of the paper's B) and of its stiffness damping.
#include <elastolearn/learn/element_state.hpp>

namespace elastolearn::learn {

/// The element's principal-stress-to-nodal-force operator (one element's block of the paper's B,
/// §4.1): column k = nodal forces [N per Pa] of a unit principal stress k, i.e. rows 3a + c hold
/// −vol (v_k · g_a) U(c, k). Local dofs ordered x0, y0, z0, x1, ….
Eigen::Matrix<double, 12, 3> element_force_operator(
    const fem::TetRestData& rest, const material::PrincipalFrame& frame);

/// The element's stiffness-damping force [N/s] per unit coefficient (α₁ or Δα₁) of an eigen-form
/// damping tangent dP/dF (material::damping_tangent): −vol (dP/dF : Ḟ) g_a. Local dofs ordered
/// x0, y0, z0, x1, ….
Vec12 element_stiffness_damping_force(const fem::TetRestData& rest, const ElementState& state,
    const material::PrincipalTangent& tangent);

/// The element's stiffness-damping force per unit α₁ as a linear function of a principal stress
/// and its stretch derivative: column c maps entry c of [p̂; vec(∂p̂/∂σ)] (3 + 9, column-major)
/// to the nodal forces −vol (dP/dF : Ḟ) g_a of material::damping_tangent of p̂ (of kind `kind`)
/// [N/s per Pa]. Applied to an RBF unknown's output and gradient (RbfDesign::output_matrix) it
/// gives that unknown's share of the nominal α₁'s action on the corrected stiffness
/// (material::ElementStress::damped).
Eigen::Matrix<double, 12, 12> element_stiffness_damping_operator(
    const fem::TetRestData& rest, const ElementState& state, material::DampingTangent kind);

} // namespace elastolearn::learn
