#pragma once
/// \file Selecting vertices of a rest mesh by position (for boundary conditions and loads).
/// Every function returns sorted vertex indices and only considers vertices used by some tet.
#include <elastolearn/mesh/tet_mesh.hpp>

#include <vector>

namespace elastolearn::mesh {

/// Vertices whose rest position lies in the closed box (boundaries included).
std::vector<int> vertices_in_box(const TetMesh& mesh, const Box3& box);

/// Vertices with |x[axis] − value| ≤ tol. axis ∈ {0,1,2}; tol ≥ 0 [m]. Throws InputError on a bad
/// axis or negative/non-finite tol.
std::vector<int> vertices_near_plane(const TetMesh& mesh, int axis, double value, double tol);

/// Vertices within tol of the smallest rest coordinate along `axis` (e.g. the clamped end of a
/// bar).
std::vector<int> vertices_with_min_coordinate(const TetMesh& mesh, int axis, double tol);

/// Vertices within tol of the largest rest coordinate along `axis`.
std::vector<int> vertices_with_max_coordinate(const TetMesh& mesh, int axis, double tol);

} // namespace elastolearn::mesh
