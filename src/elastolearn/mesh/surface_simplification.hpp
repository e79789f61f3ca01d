#pragma once
/// \file Simplifying a closed triangle surface by quadric-error edge collapses (Garland &
/// Heckbert 1997), used to bring a detailed scan down to a face count that a coarse tet mesh can
/// resolve.
#include <elastolearn/mesh/surface_mesh.hpp>

namespace elastolearn::mesh {

/// Collapses edges in order of increasing quadric error until at most `target_faces` faces remain
/// or no edge can be collapsed safely. A collapse is skipped if it would break the manifold link
/// condition, flip or strongly tilt (> ~70°) a neighbouring face, or make a face degenerate, so a
/// closed manifold stays closed and manifold. Deterministic. Unreferenced vertices are dropped.
/// Throws InputError if target_faces < 4.
SurfaceMesh simplify_surface(const SurfaceMesh& surface, int target_faces);

} // namespace elastolearn::mesh
