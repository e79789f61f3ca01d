#pragma once
/// \file Closing small holes in a triangle surface (scans often have a few), so TetGen can mesh it.
#include <elastolearn/mesh/surface_mesh.hpp>

namespace elastolearn::mesh {

/// Fills every boundary loop: a 3-edge loop with one triangle, a longer loop with a fan around a
/// new vertex at the loop's centroid. New faces follow the orientation of the faces around the
/// hole. `holes_filled` (optional) receives the number of loops closed. The caller should check
/// is_closed() afterwards: a loop through a non-manifold vertex is left open.
SurfaceMesh fill_holes(const SurfaceMesh& surface, int* holes_filled = nullptr);

} // namespace elastolearn::mesh
