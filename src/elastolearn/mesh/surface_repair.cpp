#include <elastolearn/mesh/surface_repair.hpp>

#include <map>
#include <set>
#include <vector>

namespace elastolearn::mesh {

SurfaceMesh fill_holes(const SurfaceMesh& surface, int* holes_filled) {
  // Boundary half-edges: directed face edges (a→b) whose twin (b→a) is missing.
  std::set<std::pair<int, int>> directed;
  for (Eigen::Index f = 0; f < surface.faces.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      directed.insert({ surface.faces(f, k), surface.faces(f, (k + 1) % 3) });
  std::multimap<int, int> next; // a → b along the boundary
  for (const auto& [a, b] : directed)
    if (!directed.count({ b, a }))
      next.emplace(a, b);

  std::vector<Vec3> new_vertices;
  std::vector<std::array<int, 3>> new_faces;
  int filled = 0;
  std::set<std::pair<int, int>> used;
  const int n = static_cast<int>(surface.vertices.rows());
  for (const auto& [start, second] : next) {
    if (used.count({ start, second }))
      continue;
    // Walk the loop; give up on branching (non-manifold) boundary vertices.
    std::vector<int> loop { start };
    int a = start, b = second;
    bool ok = true;
    while (true) {
      used.insert({ a, b });
      if (b == start)
        break;
      if (next.count(b) != 1 || loop.size() > next.size()) {
        ok = false;
        break;
      }
      loop.push_back(b);
      a = b;
      b = next.find(b)->second;
    }
    if (!ok || loop.size() < 3)
      continue;
    ++filled;
    // The hole's faces run opposite to the loop direction (a→b is a face edge; fill with b→a).
    if (loop.size() == 3) {
      new_faces.push_back({ loop[0], loop[2], loop[1] });
      continue;
    }
    Vec3 centroid = Vec3::Zero();
    for (int v : loop)
      centroid += surface.vertices.row(v).transpose();
    centroid /= static_cast<double>(loop.size());
    const int c = n + static_cast<int>(new_vertices.size());
    new_vertices.push_back(centroid);
    for (std::size_t i = 0; i < loop.size(); ++i)
      new_faces.push_back({ c, loop[(i + 1) % loop.size()], loop[i] });
  }

  SurfaceMesh out;
  out.vertices.resize(n + static_cast<Eigen::Index>(new_vertices.size()), 3);
  out.vertices.topRows(n) = surface.vertices;
  for (std::size_t i = 0; i < new_vertices.size(); ++i)
    out.vertices.row(n + static_cast<Eigen::Index>(i)) = new_vertices[i];
  out.faces.resize(surface.faces.rows() + static_cast<Eigen::Index>(new_faces.size()), 3);
  out.faces.topRows(surface.faces.rows()) = surface.faces;
  for (std::size_t i = 0; i < new_faces.size(); ++i)
    out.faces.row(surface.faces.rows() + static_cast<Eigen::Index>(i)) << new_faces[i][0],
        new_faces[i][1], new_faces[i][2];
  if (holes_filled)
    *holes_filled = filled;
  return out;
}

} // namespace elastolearn::mesh
