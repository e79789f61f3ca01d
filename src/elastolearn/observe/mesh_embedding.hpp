#pragma once
/// \file Observing a motion through another mesh (paper 000 §7.3, coarsening): the points of a
/// second mesh (e.g. a coarse mesh's vertices) located in the rest shape of the mesh that moved
/// (the fine mesh), each in the tet that contains it, and carried along by that tet's motion —
/// the affine (barycentric) interpolation of its four vertices, which is what the fine FEM's
/// piecewise-linear displacement field gives there.
#include <elastolearn/core/types.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <string>
#include <vector>

namespace elastolearn::observe {

/// Points embedded in a host tet mesh's rest shape.
struct MeshEmbedding {
  /// Per point: the host tet, and its four barycentric weights (summing to 1; a weight within
  /// 1e-12 of 0 is set to 0 and the rest renormalised, so a point on a host vertex has weight
  /// exactly 1 there and maps to that vertex's position bit for bit).
  std::vector<int> tets;
  std::vector<Eigen::Vector4d> weights;
  /// Largest distance [m] of a point outside its host tet (0 for points inside).
  double largest_outside = 0;

  int num_points() const { return static_cast<int>(tets.size()); }

  /// The points' positions (k × 3 [m]) when the host's vertices are at `host_positions` (n × 3,
  /// the host's vertex order; e.g. a frame of its trajectory); `host_tets` are the host's tets.
  Positions map(const Tets& host_tets, ConstRef<Positions> host_positions) const;
};

/// Locate each row of `points` (k × 3 [m], rest coordinates) in `host`'s rest shape: the tet that
/// contains it or, for a point up to `tolerance` [m] outside the host (round-off on its
/// boundary), the nearest tet by distance to the tet's face planes. A uniform grid over the tets'
/// bounding boxes keeps this O(k + m) for meshes of even element size.
/// Throws InputError("<what> <i>", ...) naming the first point farther than `tolerance` outside
/// the host, with its position and distance; InputError for a negative tolerance.
MeshEmbedding embed_points(const mesh::TetMesh& host, ConstRef<Positions> points, double tolerance,
    const std::string& what = "point");

} // namespace elastolearn::observe
