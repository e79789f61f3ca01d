#pragma once
/// \file Reading any supported tet-mesh file, chosen by extension.
#include <elastolearn/mesh/tet_mesh.hpp>

#include <filesystem>
#include <vector>

namespace elastolearn::mesh {

/// Reads a tet mesh: `.node`/`.ele` (TetGen; either file or the stem of both), `.msh` (Gmsh ASCII
/// v2/v4.1), `.veg` (Vega). Throws InputError naming the file for an unknown extension and for
/// every reader error (see tetgen_io.hpp, gmsh_io.hpp, vega_io.hpp).
TetMesh read_tet_mesh(const std::filesystem::path& path);

/// The files read_tet_mesh(path) reads: both `<stem>.node` and `<stem>.ele` for a TetGen path
/// (either file or the stem), else `path` itself. Lets a command refuse to overwrite any of them.
std::vector<std::filesystem::path> tet_mesh_files(const std::filesystem::path& path);

} // namespace elastolearn::mesh
