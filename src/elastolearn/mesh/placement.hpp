#pragma once
/// \file Placing a mesh in the world: uniform scale, rotation, translation (the scene file's
/// `mesh.scale`, `mesh.rotate_deg`, `mesh.translate`).
#include <elastolearn/core/types.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <string>

namespace elastolearn::mesh {

/// The similarity x ↦ R·(s·x) + t. R rotates by rotate_deg[0] degrees about the world x axis,
/// then rotate_deg[1] about the world y axis, then rotate_deg[2] about the world z axis
/// (extrinsic x-y-z, i.e. R = Rz·Ry·Rx), each counter-clockwise seen from the positive end of
/// the axis (right-hand rule). The scale must be positive: a negative one would mirror the mesh
/// and turn every tet inside out.
struct Placement {
  double scale = 1; ///< uniform scale factor, > 0
  Vec3 rotate_deg = Vec3::Zero(); ///< [degrees] about world x, then y, then z
  Vec3 translate = Vec3::Zero(); ///< [m], applied last

  /// R = Rz·Ry·Rx (a proper rotation: orthogonal, determinant +1).
  Mat3 rotation() const;
  /// True if this placement changes nothing (scale 1, no rotation, no translation).
  bool is_identity() const;
  /// Throws InputError(field "scale" / "rotate_deg" / "translate") for a scale that is not a
  /// positive finite number or non-finite angles or offsets.
  void validate() const;
};

/// Every row p of `positions` mapped to R·(s·p) + t.
Positions place(ConstRef<Positions> positions, const Placement& placement);

/// The inverse map: every row q mapped to Rᵀ·(q − t) / s.
Positions unplace(ConstRef<Positions> positions, const Placement& placement);

/// `mesh` with placed rest positions and the same tets. Orientation is kept (R is proper and
/// s > 0), and every tet volume is multiplied by s³. `source` names the mesh in errors.
TetMesh place(const TetMesh& mesh, const Placement& placement, const std::string& source = "mesh");

} // namespace elastolearn::mesh
