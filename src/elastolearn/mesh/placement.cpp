#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/placement.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace elastolearn::mesh {

Mat3 Placement::rotation() const {
  const Vec3 r = rotate_deg * (std::numbers::pi / 180);
  // Extrinsic x, then y, then z: the last rotation applied is the leftmost factor.
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY())
      * Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

bool Placement::is_identity() const {
  return scale == 1 && rotate_deg.isZero(0) && translate.isZero(0);
}

void Placement::validate() const {
  if (!(scale > 0 && std::isfinite(scale)))
    throw InputError("scale",
        "must be a positive number (a negative scale would mirror the mesh and invert its tets)");
  if (!rotate_deg.allFinite())
    throw InputError("rotate_deg", "must be finite");
  if (!translate.allFinite())
    throw InputError("translate", "must be finite");
}

Positions place(ConstRef<Positions> positions, const Placement& placement) {
  const Mat3 A = placement.scale * placement.rotation();
  Positions out = (positions * A.transpose()).rowwise() + placement.translate.transpose();
  return out;
}

Positions unplace(ConstRef<Positions> positions, const Placement& placement) {
  const Mat3 A_inverse = placement.rotation().transpose() / placement.scale;
  Positions out = (positions.rowwise() - placement.translate.transpose()) * A_inverse.transpose();
  return out;
}

TetMesh place(const TetMesh& mesh, const Placement& placement, const std::string& source) {
  placement.validate();
  if (placement.is_identity())
    return mesh;
  return TetMesh(place(mesh.rest_positions(), placement), mesh.tets(), source);
}

} // namespace elastolearn::mesh
