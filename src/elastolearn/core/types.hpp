#pragma once
/// \file Common Eigen aliases. Storage conventions used throughout elastolearn:
/// - vertex arrays are n×3 row-major, so `flatten(x)` is the 3n vector (x0,y0,z0,x1,...);
/// - a 3×3 matrix M is vectorised column-major: vec(M)[i + 3 j] = M(i, j) (Eigen's default);
///   9×9 derivatives such as dP/dF use this vec on both sides: D(a, b) = ∂vec(P)_a / ∂vec(F)_b.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace elastolearn {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Mat9x12 = Eigen::Matrix<double, 9, 12>;
using VecX = Eigen::VectorXd;
using VecXi = Eigen::VectorXi;
using MatX = Eigen::MatrixXd;

/// n×3 vertex positions (or velocities, forces), row-major.
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// m×4 tetrahedron vertex indices, row-major.
using Tets = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;
/// f×3 triangle vertex indices, row-major.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// e×2 edge vertex indices, row-major.
using Edges = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

using Box3 = Eigen::AlignedBox3d;

/// Read-only view of any dense Eigen expression (one alias, as in IPC Toolkit).
template <typename T> using ConstRef = const Eigen::Ref<const T>&;

/// View an n×3 row-major array as its flat 3n vector (no copy).
inline Eigen::Map<VecX> flatten(Positions& x) {
  return { x.data(), x.size() };
}
inline Eigen::Map<const VecX> flatten(const Positions& x) {
  return { x.data(), x.size() };
}
/// View a flat 3n vector as n×3 rows (no copy).
inline Eigen::Map<Positions> unflatten(VecX& v) {
  return { v.data(), v.size() / 3, 3 };
}
inline Eigen::Map<const Positions> unflatten(const VecX& v) {
  return { v.data(), v.size() / 3, 3 };
}

} // namespace elastolearn
