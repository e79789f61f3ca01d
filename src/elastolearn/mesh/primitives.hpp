#pragma once
/// \file Procedural tet meshes: a box bar and a ball, both conforming and positively oriented.
#include <elastolearn/mesh/tet_mesh.hpp>

#include <array>

namespace elastolearn::mesh {

/// The most tets a generated mesh may have. Far beyond what the solvers handle in reasonable
/// time (~10⁶ tets), it keeps every index in `int` and the memory a mistyped count asks for
/// bounded (≈ 1 GB), so that a count of 10¹⁵ is a clear error instead of an allocation failure.
constexpr long long kMaxGeneratedTets = 10'000'000;

/// The box [0, size.x]×[0, size.y]×[0, size.z] [m] split into cells[0]×cells[1]×cells[2] equal
/// cuboids, each cut into 6 tets around its main diagonal (the Kuhn/Freudenthal pattern, the same
/// in every cell, so neighbouring cells share their face diagonals: conforming).
/// Vertex (i, j, k) of the lattice has index i + (cells[0]+1)·(j + (cells[1]+1)·k).
/// Throws InputError if a size is not positive/finite, a cell count is < 1 or the mesh would have
/// more than kMaxGeneratedTets tets (6·cells[0]·cells[1]·cells[2]).
TetMesh make_box_bar(const Vec3& size, const std::array<int, 3>& cells);

/// A ball of radius `radius` [m] centred at the origin, with about `target_tets` tets (within ±30 %
/// for target_tets ≥ 48; at least 48 tets).
///
/// Construction (deterministic, no TetGen): the cube [-1,1]³ is split into a×b×c cells
/// (a ≤ b ≤ c ≤ a+1, chosen so that 6abc is closest to the target) and each cell into 6 Kuhn tets
/// whose diagonal points away from the centre (mirrored per octant, which keeps the lattice
/// conforming); the cube is then mapped onto the ball by the radial map
/// p ↦ radius · p · ‖p‖∞ / ‖p‖₂, which sends the cube surface onto the sphere. Surface vertices lie
/// exactly on the sphere, so the mesh volume approaches 4/3·π·r³ from below as O(h²).
/// Throws InputError if radius is not positive/finite, target_tets < 1 or target_tets >
/// kMaxGeneratedTets.
TetMesh make_sphere(double radius, int target_tets);

} // namespace elastolearn::mesh
