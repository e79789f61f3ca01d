#pragma once
/// \file Validation of rest tet meshes shared by the TetMesh constructor and the file readers, so
/// that a reader can name the file line of a bad vertex or tet.
#include <elastolearn/core/types.hpp>

#include <string>
#include <vector>

namespace elastolearn::mesh {

/// Where each vertex / tet came from in a file (1-based line numbers); empty vectors = unknown.
struct SourceLines {
  std::vector<int> vertex_lines; ///< line of vertex i, or empty
  std::vector<int> tet_lines; ///< line of tet t, or empty
};

/// Relative threshold below which a tet counts as degenerate: |6V| <= kDegenerateTolerance · L³,
/// L the longest edge (matches MeshQuality::num_degenerate).
inline constexpr double kDegenerateTolerance = 1e-12;

/// Checks the TetMesh invariants: at least one tet, finite coordinates, indices in range, every
/// tet positively oriented and not degenerate. Throws InputError whose `where` is `source`
/// (or "source:line" when `lines` gives the line), naming the vertex/tet index and the offending
/// value (coordinate, index, or signed volume).
void validate_tet_mesh(const Positions& rest, const Tets& tets, const std::string& source,
    const SourceLines* lines = nullptr);

/// Signed volume test of one tet: returns 6V = det[b-a, c-a, d-a] and sets `degenerate` when
/// |6V| <= kDegenerateTolerance · (longest edge)³.
double six_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, bool& degenerate);

} // namespace elastolearn::mesh
