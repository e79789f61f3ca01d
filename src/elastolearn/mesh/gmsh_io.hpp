#pragma once
/// \file Gmsh `.msh` tet meshes, ASCII format versions 2.x and 4.1 (read).
///
/// Only 4-node tetrahedra (element type 4) are read; other elements (points, lines, triangles,
/// …) are ignored. Node tags may be non-contiguous; nodes used by no tetrahedron are dropped and
/// the rest keep their file order. Binary files and version 4.0 are rejected with a clear error.
#include <elastolearn/mesh/tet_mesh.hpp>

#include <filesystem>

namespace elastolearn::mesh {

/// Reads a Gmsh ASCII `.msh` (v2 or v4.1). Throws InputError naming the file and line for a
/// missing or truncated section, unsupported version, duplicate or unknown node tags, NaN/inf
/// coordinates, no tetrahedra, and inverted or degenerate tets (det[x1-x0, x2-x0, x3-x0] must be
/// > 0, which is Gmsh's own convention for element type 4).
TetMesh read_gmsh(const std::filesystem::path& path);

} // namespace elastolearn::mesh
