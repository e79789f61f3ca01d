#pragma once
/// \file Vega FEM `.veg` tet meshes (read).
///
/// Sections `*VERTICES` (header `<n> 3 0 0`, then `<id> x y z`, ids 1-based and consecutive) and
/// `*ELEMENTS` followed by the element type `TET`, a header `<m> 4 0` and lines `<id> v0 v1 v2 v3`
/// (1-based vertex ids). Other sections (`*MATERIAL`, `*REGION`, `*SET`, …) are ignored; `#`
/// starts a comment; commas count as separators. `*INCLUDE` and CUBIC elements are rejected.
#include <elastolearn/mesh/tet_mesh.hpp>

#include <filesystem>

namespace elastolearn::mesh {

/// Reads a `.veg` file. Throws InputError naming the file and line for a missing section,
/// truncated data, bad or out-of-range ids, NaN/inf coordinates, non-TET elements, and inverted or
/// degenerate tets (tets must satisfy det[x1-x0, x2-x0, x3-x0] > 0).
TetMesh read_vega(const std::filesystem::path& path);

} // namespace elastolearn::mesh
