#include <elastolearn/mesh/tet_mesh.hpp>

#include <elastolearn/mesh/mesh_validation.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace elastolearn::mesh {

namespace {

/// The four faces of a positively oriented tet (a,b,c,d), each counter-clockwise seen from
/// outside: face k is opposite vertex k.
constexpr int kTetFaces[4][3] = { { 1, 2, 3 }, { 0, 3, 2 }, { 0, 1, 3 }, { 0, 2, 1 } };

struct TripleHash {
  std::size_t operator()(const std::array<int, 3>& k) const noexcept {
    std::size_t h = static_cast<std::size_t>(k[0]) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::size_t>(k[1]) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h ^= static_cast<std::size_t>(k[2]) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    return h;
  }
};

} // namespace

TetMesh::TetMesh(Positions rest, Tets tets, const std::string& source)
    : m_rest(std::move(rest))
    , m_tets(std::move(tets)) {
  validate_tet_mesh(m_rest, m_tets, source);

  // Faces that belong to exactly one tet are on the boundary. Count sorted triples, then emit the
  // once-seen faces in tet order (deterministic) with the owning tet's outward orientation.
  std::unordered_map<std::array<int, 3>, int, TripleHash> count;
  count.reserve(static_cast<std::size_t>(m_tets.rows()) * 4);
  const auto key = [&](Eigen::Index t, int f) {
    std::array<int, 3> k { m_tets(t, kTetFaces[f][0]), m_tets(t, kTetFaces[f][1]),
      m_tets(t, kTetFaces[f][2]) };
    std::sort(k.begin(), k.end());
    return k;
  };
  for (Eigen::Index t = 0; t < m_tets.rows(); ++t)
    for (int f = 0; f < 4; ++f)
      ++count[key(t, f)];
  std::vector<std::array<int, 3>> faces;
  for (Eigen::Index t = 0; t < m_tets.rows(); ++t)
    for (int f = 0; f < 4; ++f)
      if (count[key(t, f)] == 1)
        faces.push_back(
            { m_tets(t, kTetFaces[f][0]), m_tets(t, kTetFaces[f][1]), m_tets(t, kTetFaces[f][2]) });
  m_surface_faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  std::vector<char> on_surface(static_cast<std::size_t>(m_rest.rows()), 0);
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      m_surface_faces(static_cast<Eigen::Index>(i), k) = faces[i][k];
      on_surface[static_cast<std::size_t>(faces[i][k])] = 1;
    }
  for (int v = 0; v < num_vertices(); ++v)
    if (on_surface[static_cast<std::size_t>(v)])
      m_surface_vertices.push_back(v);
}

Box3 TetMesh::bounding_box() const {
  Box3 box;
  for (Eigen::Index i = 0; i < m_rest.rows(); ++i)
    box.extend(Vec3(m_rest.row(i)));
  return box;
}

VecX TetMesh::element_volumes() const {
  VecX v(m_tets.rows());
  for (Eigen::Index t = 0; t < m_tets.rows(); ++t)
    v[t] = signed_volume(m_rest.row(m_tets(t, 0)), m_rest.row(m_tets(t, 1)),
        m_rest.row(m_tets(t, 2)), m_rest.row(m_tets(t, 3)));
  return v;
}

MeshQuality TetMesh::quality() const {
  MeshQuality q;
  q.min_volume = std::numeric_limits<double>::infinity();
  q.max_volume = -std::numeric_limits<double>::infinity();
  q.min_dihedral_deg = 180.0;
  q.max_dihedral_deg = 0.0;
  q.max_radius_ratio = 0.0;
  // Edge (i,j) of a tet is shared by the two faces opposite the other two vertices k,l; the
  // dihedral angle there is π minus the angle between those faces' outward normals.
  constexpr int kEdges[6][4] = { { 0, 1, 2, 3 }, { 0, 2, 1, 3 }, { 0, 3, 1, 2 }, { 1, 2, 0, 3 },
    { 1, 3, 0, 2 }, { 2, 3, 0, 1 } };
  for (Eigen::Index t = 0; t < m_tets.rows(); ++t) {
    std::array<Vec3, 4> x;
    for (int k = 0; k < 4; ++k)
      x[k] = m_rest.row(m_tets(t, k));
    bool degenerate = false;
    const double det = six_volume(x[0], x[1], x[2], x[3], degenerate);
    if (degenerate)
      ++q.num_degenerate;
    q.min_volume = std::min(q.min_volume, det / 6.0);
    q.max_volume = std::max(q.max_volume, det / 6.0);

    std::array<Vec3, 4> normal; // area-weighted outward normals (×2)
    double area_sum = 0;
    for (int f = 0; f < 4; ++f) {
      const Vec3& a = x[kTetFaces[f][0]];
      normal[f] = (x[kTetFaces[f][1]] - a).cross(x[kTetFaces[f][2]] - a);
      area_sum += 0.5 * normal[f].norm();
    }
    for (const auto& e : kEdges) {
      const Vec3& n1 = normal[e[2]];
      const Vec3& n2 = normal[e[3]];
      const double c = std::clamp(n1.dot(n2) / (n1.norm() * n2.norm()), -1.0, 1.0);
      const double angle = 180.0 - std::acos(c) * 180.0 / std::numbers::pi;
      q.min_dihedral_deg = std::min(q.min_dihedral_deg, angle);
      q.max_dihedral_deg = std::max(q.max_dihedral_deg, angle);
    }
    // Circumradius R = |a²(b×c) + b²(c×a) + c²(a×b)| / (2·6V); inradius r = 3V / area.
    const Vec3 a = x[1] - x[0], b = x[2] - x[0], c = x[3] - x[0];
    const Vec3 w = a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a)
        + c.squaredNorm() * a.cross(b);
    const double circumradius = w.norm() / (2.0 * std::abs(det));
    const double inradius = 3.0 * std::abs(det) / 6.0 / area_sum;
    q.max_radius_ratio = std::max(q.max_radius_ratio, circumradius / (3.0 * inradius));
  }
  return q;
}

double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

} // namespace elastolearn::mesh
