#pragma once
/// \file TetGen `.node` / `.ele` tet meshes (read and write).
///
/// `.node`: header `<#points> 3 <#attributes> <#boundary markers 0|1>`, then `<id> x y z [attr…]
/// [marker]`. `.ele`: header `<#tets> <4|10> <#attributes>`, then `<id> n0 n1 n2 n3 [… attr]`
/// (for 10-node tets the first four, the corners, are used). `#` starts a comment. Indices are
/// 0- or 1-based, decided by the first point's id; ids must be consecutive.
#include <elastolearn/mesh/tet_mesh.hpp>

#include <array>
#include <filesystem>

namespace elastolearn::mesh {

/// Reads `<stem>.node` and `<stem>.ele`; `path` may be the stem or either file.
/// Throws InputError naming the file and line for unreadable or truncated files, bad counts,
/// non-consecutive ids, out-of-range indices, NaN/inf coordinates, and inverted or degenerate tets
/// (tets must be positively oriented: det[x1-x0, x2-x0, x3-x0] > 0, TetGen's own output order).
TetMesh read_tetgen(const std::filesystem::path& path);

/// Writes `<stem>.node` and `<stem>.ele` (0-based, shortest round-trip decimal coordinates, so
/// reading them back gives identical numbers). Each file is written to a temporary file and
/// renamed, so a failure leaves no half-written output. Throws InputError if it cannot write.
void write_tetgen(const std::filesystem::path& stem, const TetMesh& mesh);

/// `path` without a `.node` / `.ele` extension (other extensions are kept).
std::filesystem::path tetgen_stem(const std::filesystem::path& path);

/// `<stem>.node` and `<stem>.ele` for `path` (either file or their stem): the files read_tetgen
/// reads and write_tetgen writes.
std::array<std::filesystem::path, 2> tetgen_files(const std::filesystem::path& path);

} // namespace elastolearn::mesh
