#include <elastolearn/capture/surface_distance.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastolearn::capture {

double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0)
    return ap.norm(); // vertex a
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3)
    return bp.norm(); // vertex b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
    return (p - (a + d1 / (d1 - d3) * ab)).norm(); // edge ab
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6)
    return cp.norm(); // vertex c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
    return (p - (a + d2 / (d2 - d6) * ac)).norm(); // edge ac
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm(); // edge bc
  const double denom = 1 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm(); // face
}

SurfaceDistance::SurfaceDistance(const Faces& faces, int num_vertices, int subdivision)
    : m_faces(faces)
    , m_samples(sample_surface(faces, subdivision))
    , m_offsets(static_cast<std::size_t>(num_vertices) + 1, 0) {
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int j = 0; j < 3; ++j)
      ++m_offsets[static_cast<std::size_t>(faces(f, j)) + 1];
  for (int v = 0; v < num_vertices; ++v)
    m_offsets[v + 1] += m_offsets[v];
  m_vertex_faces.resize(static_cast<std::size_t>(m_offsets.back()));
  std::vector<int> next(m_offsets.begin(), m_offsets.end() - 1);
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int j = 0; j < 3; ++j)
      m_vertex_faces[static_cast<std::size_t>(next[faces(f, j)]++)] = static_cast<int>(f);
}

void SurfaceDistance::distances(
    ConstRef<Positions> x, ConstRef<Positions> points, VecX& out) const {
  out.resize(points.rows());
  const CloudIndex index(m_samples.positions(x));
  tbb::parallel_for(Eigen::Index(0), points.rows(), [&](Eigen::Index i) {
    const Vec3 p = points.row(i).transpose();
    const auto [k, d2] = index.nearest(p);
    double best = std::sqrt(d2); // the sample itself is on the surface: an upper bound
    if (k >= 0)
      for (int j = 0; j < 3; ++j) {
        const int v = m_samples.vertices(k, j);
        for (int o = m_offsets[v]; o < m_offsets[v + 1]; ++o) {
          const int f = m_vertex_faces[static_cast<std::size_t>(o)];
          best = std::min(best,
              point_triangle_distance(p, x.row(m_faces(f, 0)).transpose(),
                  x.row(m_faces(f, 1)).transpose(), x.row(m_faces(f, 2)).transpose()));
        }
      }
    out[i] = best;
  });
}

double SurfaceDistance::rms(ConstRef<Positions> x, ConstRef<Positions> points) const {
  if (points.rows() == 0)
    return 0;
  VecX d;
  distances(x, points, d);
  return std::sqrt(d.squaredNorm() / double(points.rows()));
}

} // namespace elastolearn::capture
