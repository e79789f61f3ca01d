#include <elastolearn/mesh/surface_simplification.hpp>

#include <elastolearn/core/error.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <queue>

namespace elastolearn::mesh {

namespace {

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

struct Candidate {
  double cost;
  int u, v;
  int stamp_u, stamp_v;
  Vec3 target;
  bool operator>(const Candidate& o) const {
    if (cost != o.cost)
      return cost > o.cost;
    return std::tie(u, v) > std::tie(o.u, o.v); // deterministic tie-break
  }
};

class Simplifier {
  public:
  explicit Simplifier(const SurfaceMesh& s) {
    const auto n = static_cast<std::size_t>(s.vertices.rows());
    m_pos.resize(n);
    m_quadric.assign(n, Mat4::Zero());
    m_stamp.assign(n, 0);
    m_vertex_alive.assign(n, 1);
    m_vertex_faces.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      m_pos[i] = s.vertices.row(static_cast<Eigen::Index>(i));
    for (Eigen::Index f = 0; f < s.faces.rows(); ++f) {
      m_faces.push_back({ s.faces(f, 0), s.faces(f, 1), s.faces(f, 2) });
      m_face_alive.push_back(1);
      for (int k = 0; k < 3; ++k)
        m_vertex_faces[static_cast<std::size_t>(s.faces(f, k))].push_back(static_cast<int>(f));
      const Vec3 a = m_pos[static_cast<std::size_t>(s.faces(f, 0))];
      const Vec3 nrm = (m_pos[static_cast<std::size_t>(s.faces(f, 1))] - a)
                           .cross(m_pos[static_cast<std::size_t>(s.faces(f, 2))] - a);
      const double area2 = nrm.norm();
      if (area2 <= 0)
        continue;
      Vec4 plane;
      plane << nrm / area2, -nrm.dot(a) / area2;
      const Mat4 k = 0.5 * area2 * plane * plane.transpose();
      for (int c = 0; c < 3; ++c)
        m_quadric[static_cast<std::size_t>(s.faces(f, c))] += k;
    }
    m_alive_faces = static_cast<int>(m_faces.size());
    for (std::size_t f = 0; f < m_faces.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = m_faces[f][k], b = m_faces[f][static_cast<std::size_t>((k + 1) % 3)];
        if (a < b)
          push(a, b);
      }
  }

  void run(int target_faces) {
    while (m_alive_faces > target_faces && !m_queue.empty()) {
      const Candidate c = m_queue.top();
      m_queue.pop();
      if (!m_vertex_alive[c.u] || !m_vertex_alive[c.v])
        continue;
      if (c.stamp_u != m_stamp[c.u] || c.stamp_v != m_stamp[c.v])
        continue;
      collapse(c.u, c.v, c.target);
    }
  }

  SurfaceMesh result() const {
    SurfaceMesh s;
    s.vertices.resize(static_cast<Eigen::Index>(m_pos.size()), 3);
    for (std::size_t i = 0; i < m_pos.size(); ++i)
      s.vertices.row(static_cast<Eigen::Index>(i)) = m_pos[i];
    s.faces.resize(m_alive_faces, 3);
    Eigen::Index row = 0;
    for (std::size_t f = 0; f < m_faces.size(); ++f)
      if (m_face_alive[f])
        s.faces.row(row++) << m_faces[f][0], m_faces[f][1], m_faces[f][2];
    return remove_unreferenced_vertices(s);
  }

  private:
  void push(int u, int v) {
    const Mat4 q = m_quadric[u] + m_quadric[v];
    const Vec3& pu = m_pos[u];
    const Vec3& pv = m_pos[v];
    const auto cost = [&](const Vec3& p) {
      Vec4 h;
      h << p, 1.0;
      return std::max(0.0, h.dot(q * h));
    };
    // Optimal point if the 3×3 system is well conditioned and the point stays near the edge.
    std::array<Vec3, 4> options { pu, pv, 0.5 * (pu + pv), 0.5 * (pu + pv) };
    int count = 3;
    const Mat3 a = q.topLeftCorner<3, 3>();
    Eigen::FullPivLU<Mat3> lu(a);
    if (lu.rank() == 3) {
      const Vec3 p = lu.solve(-q.topRightCorner<3, 1>());
      if ((p - options[2]).norm() <= 0.5 * (pu - pv).norm())
        options[static_cast<std::size_t>(count++)] = p;
    }
    int best = 0;
    for (int i = 1; i < count; ++i)
      if (cost(options[i]) < cost(options[best]))
        best = i;
    m_queue.push({ cost(options[best]), u, v, m_stamp[u], m_stamp[v], options[best] });
  }

  std::vector<int> alive_faces_of(int v) {
    auto& list = m_vertex_faces[v];
    list.erase(std::remove_if(list.begin(), list.end(), [&](int f) { return !m_face_alive[f]; }),
        list.end());
    return list;
  }

  std::vector<int> neighbours(const std::vector<int>& faces, int v) const {
    std::vector<int> out;
    for (int f : faces)
      for (int w : m_faces[f])
        if (w != v)
          out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  void collapse(int u, int v, const Vec3& target) {
    const std::vector<int> fu = alive_faces_of(u), fv = alive_faces_of(v);
    std::vector<int> shared;
    for (int f : fu)
      if (std::find(fv.begin(), fv.end(), f) != fv.end())
        shared.push_back(f);
    if (shared.size() != 2)
      return;
    // Link condition: the common neighbours of u and v are exactly the two opposite vertices.
    const std::vector<int> nu = neighbours(fu, u), nv = neighbours(fv, v);
    std::vector<int> common;
    std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
    if (common.size() != 2)
      return;
    if (m_alive_faces - 2 < 4)
      return;
    // No neighbouring face may flip, tilt by more than ~70°, or become degenerate.
    for (const std::vector<int>* faces : { &fu, &fv })
      for (int f : *faces) {
        if (std::find(shared.begin(), shared.end(), f) != shared.end())
          continue;
        const auto& t = m_faces[f];
        std::array<Vec3, 3> before, after;
        for (int k = 0; k < 3; ++k) {
          before[k] = m_pos[t[k]];
          after[k] = (t[k] == u || t[k] == v) ? target : before[k];
        }
        const Vec3 n0 = (before[1] - before[0]).cross(before[2] - before[0]);
        const Vec3 n1 = (after[1] - after[0]).cross(after[2] - after[0]);
        const double longest = std::max({ (after[1] - after[0]).squaredNorm(),
            (after[2] - after[1]).squaredNorm(), (after[0] - after[2]).squaredNorm() });
        if (n1.norm() <= 1e-3 * longest)
          return; // needle or flat triangle
        if (n0.dot(n1) <= 0.34 * n0.norm() * n1.norm())
          return; // tilt > ~70°
      }
    for (int f : shared)
      m_face_alive[f] = 0;
    m_alive_faces -= 2;
    for (int f : fv) {
      if (!m_face_alive[f])
        continue;
      for (int& w : m_faces[f])
        if (w == v)
          w = u;
      m_vertex_faces[u].push_back(f);
    }
    m_vertex_alive[v] = 0;
    m_pos[u] = target;
    m_quadric[u] += m_quadric[v];
    ++m_stamp[u];
    for (int w : neighbours(alive_faces_of(u), u))
      push(std::min(u, w), std::max(u, w));
  }

  std::vector<Vec3> m_pos;
  std::vector<Mat4> m_quadric;
  std::vector<int> m_stamp;
  std::vector<char> m_vertex_alive;
  std::vector<std::vector<int>> m_vertex_faces;
  std::vector<std::array<int, 3>> m_faces;
  std::vector<char> m_face_alive;
  int m_alive_faces = 0;
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> m_queue;
};

} // namespace

SurfaceMesh simplify_surface(const SurfaceMesh& surface, int target_faces) {
  if (target_faces < 4)
    throw InputError(
        "simplify_surface", "target_faces must be >= 4, got " + std::to_string(target_faces));
  Simplifier s(surface);
  s.run(target_faces);
  return s.result();
}

} // namespace elastolearn::mesh
