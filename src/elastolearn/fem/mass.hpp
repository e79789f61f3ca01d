#pragma once
/// \file Mass matrices of linear tets with uniform density ρ [kg/m³].
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/system_matrix.hpp>
#include <elastolearn/fem/tet_element.hpp>

#include <vector>

namespace elastolearn::fem {

/// How mass is distributed (name table shared by JSON and CLI).
enum class MassType { Lumped, Consistent };
const char* to_string(MassType type);
/// Throws InputError listing the valid names.
MassType mass_type_from_string(const std::string& name);

/// Lumped vertex masses (paper 000's choice): each tet gives ρ·vol/4 to each vertex. Length n [kg].
VecX lumped_vertex_masses(
    const Tets& tets, const std::vector<TetRestData>& rest, int num_vertices, double density);

/// Per-dof lumped masses (each vertex mass repeated 3×). Length 3n.
VecX lumped_dof_masses(const VecX& vertex_masses);

/// One element's consistent mass matrix ρ·vol/20·(1 + δ_ab)·I₃ (12×12, local dofs x0, y0, z0, x1,
/// …).
Mat12 consistent_mass_block(double volume, double density);

/// Element buffer (m·144) of consistent mass blocks (consistent_mass_block), for SystemMatrix.
std::vector<double> consistent_mass_blocks(const std::vector<TetRestData>& rest, double density);

} // namespace elastolearn::fem
