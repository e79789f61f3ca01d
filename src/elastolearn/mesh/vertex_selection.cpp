#include <elastolearn/mesh/vertex_selection.hpp>

#include <elastolearn/core/error.hpp>

#include <cmath>
#include <limits>

namespace elastolearn::mesh {

namespace {

std::vector<char> used_vertices(const TetMesh& mesh) {
  std::vector<char> used(static_cast<std::size_t>(mesh.num_vertices()), 0);
  const Tets& tets = mesh.tets();
  for (Eigen::Index i = 0; i < tets.size(); ++i)
    used[static_cast<std::size_t>(tets.data()[i])] = 1;
  return used;
}

void check_axis_tol(int axis, double tol) {
  if (axis < 0 || axis > 2)
    throw InputError("vertex selection", "axis must be 0, 1 or 2, got " + std::to_string(axis));
  if (!(std::isfinite(tol) && tol >= 0))
    throw InputError("vertex selection", "tolerance must be >= 0, got " + std::to_string(tol));
}

template <typename Pred> std::vector<int> select(const TetMesh& mesh, Pred pred) {
  const auto used = used_vertices(mesh);
  std::vector<int> out;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (used[static_cast<std::size_t>(v)] && pred(Vec3(mesh.rest_positions().row(v))))
      out.push_back(v);
  return out;
}

} // namespace

std::vector<int> vertices_in_box(const TetMesh& mesh, const Box3& box) {
  return select(mesh, [&](const Vec3& p) { return box.contains(p); });
}

std::vector<int> vertices_near_plane(const TetMesh& mesh, int axis, double value, double tol) {
  check_axis_tol(axis, tol);
  return select(mesh, [&](const Vec3& p) { return std::abs(p[axis] - value) <= tol; });
}

std::vector<int> vertices_with_min_coordinate(const TetMesh& mesh, int axis, double tol) {
  check_axis_tol(axis, tol);
  double lo = std::numeric_limits<double>::infinity();
  for (int v : select(mesh, [](const Vec3&) { return true; }))
    lo = std::min(lo, mesh.rest_positions()(v, axis));
  return vertices_near_plane(mesh, axis, lo, tol);
}

std::vector<int> vertices_with_max_coordinate(const TetMesh& mesh, int axis, double tol) {
  check_axis_tol(axis, tol);
  double hi = -std::numeric_limits<double>::infinity();
  for (int v : select(mesh, [](const Vec3&) { return true; }))
    hi = std::max(hi, mesh.rest_positions()(v, axis));
  return vertices_near_plane(mesh, axis, hi, tol);
}

} // namespace elastolearn::mesh
