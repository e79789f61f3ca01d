#pragma once
/// \file Triangle surface meshes: reading OBJ/OFF/PLY/STL, closedness and enclosed volume.
#include <elastolearn/core/types.hpp>

#include <filesystem>

namespace elastolearn::mesh {

/// A triangle surface: n×3 vertex positions [m] and f×3 vertex indices (0-based). For a closed
/// surface the faces are expected counter-clockwise seen from outside (outward normals).
struct SurfaceMesh {
  Positions vertices;
  Faces faces;
};

/// Reads a surface mesh, format chosen by extension (case-insensitive):
/// - `.obj`: `v x y z` and `f a b c …` (1-based, negative = relative, `a/t/n` forms accepted);
/// - `.off`: OFF/COFF/NOFF header, counts, vertices (first 3 numbers used), `k i0 … ik-1` faces;
/// - `.ply`: ASCII or binary little-endian; element `vertex` (x, y, z of any numeric type) and
///   `face` with list property `vertex_indices`/`vertex_index`; other elements/properties skipped;
/// - `.stl`: ASCII or binary (told apart by the exact binary size); identical corner
///   coordinates are welded into one vertex.
/// Polygons are fan-triangulated (v0, vi, vi+1); triangles that repeat a vertex are dropped.
/// Throws InputError naming the file (and line for text formats) for unreadable or truncated
/// files, bad counts, out-of-range indices, NaN/inf coordinates, unsupported variants
/// (big-endian PLY), and files with no faces.
SurfaceMesh read_surface_mesh(const std::filesystem::path& path);

/// Writes an OFF file atomically (shortest round-trip decimals). Throws InputError on failure.
void write_off(const std::filesystem::path& path, const SurfaceMesh& surface);

/// True when every undirected edge is shared by exactly two faces (and there is a face).
/// Orientation consistency is not checked here.
bool is_closed(const SurfaceMesh& surface);

/// Edges of the surface used by one face (open boundary) and by more than two (non-manifold).
struct EdgeDefects {
  int boundary_edges = 0;
  int non_manifold_edges = 0;
};
EdgeDefects edge_defects(const SurfaceMesh& surface);

/// Signed volume enclosed by the surface [m³]: Σ x0·(x1×x2)/6 over faces. Positive for a closed
/// outward-oriented surface; meaningless for an open one.
double enclosed_volume(const SurfaceMesh& surface);

/// The same surface without vertices used by no face (faces re-indexed, order kept).
SurfaceMesh remove_unreferenced_vertices(const SurfaceMesh& surface);

} // namespace elastolearn::mesh
