#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/observe/mesh_embedding.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace elastolearn::observe {

namespace {

/// Barycentric weights of `x` in the tet with vertices p (columns), and the largest distance of
/// x outside one of its face planes (≤ 0 inside: b_i / |∇b_i| is the signed distance to face i).
struct Location {
  Eigen::Vector4d weights;
  double outside;
};

Location locate(const Eigen::Matrix<double, 3, 4>& p, const Vec3& x) {
  Mat3 edges;
  edges << p.col(1) - p.col(0), p.col(2) - p.col(0), p.col(3) - p.col(0);
  const Mat3 inverse = edges.inverse(); // rows: ∇b₁, ∇b₂, ∇b₃
  const Vec3 b = inverse * (x - p.col(0));
  Location l;
  l.weights << 1 - b.sum(), b;
  Eigen::Vector4d gradient_norm;
  gradient_norm << (inverse.row(0) + inverse.row(1) + inverse.row(2)).norm(), inverse.row(0).norm(),
      inverse.row(1).norm(), inverse.row(2).norm();
  l.outside = (-l.weights.array() / gradient_norm.array()).maxCoeff();
  return l;
}

/// Uniform grid of tet bounding boxes (each grown by a margin).
class TetGrid {
  public:
  TetGrid(const mesh::TetMesh& mesh, double margin) {
    const Positions& x = mesh.rest_positions();
    const Tets& tets = mesh.tets();
    const int m = mesh.num_tets();
    m_lo = mesh.bounding_box().min().array() - margin;
    const Vec3 extent = (mesh.bounding_box().max().array() + margin) - m_lo.array();
    // Cells about as large as a tet: ~m cells, at least 1 per axis.
    const double volume = std::max(extent.prod(), 1e-300);
    m_cell = std::cbrt(volume / std::max(1, m));
    for (int a = 0; a < 3; ++a) {
      m_dims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / m_cell)), 1, 1 << 10);
      m_size[a] = extent[a] / m_dims[a];
    }
    std::vector<std::pair<long, int>> entries; // (cell, tet)
    for (int e = 0; e < m; ++e) {
      Vec3 lo = x.row(tets(e, 0)).transpose(), hi = lo;
      for (int a = 1; a < 4; ++a) {
        lo = lo.cwiseMin(x.row(tets(e, a)).transpose());
        hi = hi.cwiseMax(x.row(tets(e, a)).transpose());
      }
      const auto c0 = cell_of(lo.array() - margin), c1 = cell_of(hi.array() + margin);
      for (int i = c0[0]; i <= c1[0]; ++i)
        for (int j = c0[1]; j <= c1[1]; ++j)
          for (int k = c0[2]; k <= c1[2]; ++k)
            entries.emplace_back(index(i, j, k), e);
    }
    std::sort(entries.begin(), entries.end());
    m_offsets.assign(static_cast<size_t>(m_dims[0]) * m_dims[1] * m_dims[2] + 1, 0);
    for (const auto& [cell, tet] : entries)
      ++m_offsets[cell + 1];
    for (size_t c = 1; c < m_offsets.size(); ++c)
      m_offsets[c] += m_offsets[c - 1];
    m_tets.reserve(entries.size());
    for (const auto& [cell, tet] : entries)
      m_tets.push_back(tet);
  }

  /// The tets whose grown box may contain `x` (none outside the grid).
  std::pair<const int*, const int*> candidates(const Vec3& x) const {
    for (int a = 0; a < 3; ++a)
      if (!(x[a] >= m_lo[a] && x[a] <= m_lo[a] + m_size[a] * m_dims[a]))
        return { nullptr, nullptr };
    const auto c = cell_of(x);
    const long i = index(c[0], c[1], c[2]);
    return { m_tets.data() + m_offsets[i], m_tets.data() + m_offsets[i + 1] };
  }

  private:
  std::array<int, 3> cell_of(const Vec3& x) const {
    std::array<int, 3> c;
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(
          static_cast<int>(std::floor((x[a] - m_lo[a]) / m_size[a])), 0, m_dims[a] - 1);
    return c;
  }
  long index(int i, int j, int k) const {
    return (static_cast<long>(i) * m_dims[1] + j) * m_dims[2] + k;
  }

  Vec3 m_lo;
  double m_cell = 1;
  std::array<int, 3> m_dims {};
  Vec3 m_size;
  std::vector<long> m_offsets;
  std::vector<int> m_tets;
};

} // namespace

Positions MeshEmbedding::map(const Tets& host_tets, ConstRef<Positions> host_positions) const {
  Positions out(num_points(), 3);
  for (int i = 0; i < num_points(); ++i) {
    Vec3 x = Vec3::Zero();
    for (int a = 0; a < 4; ++a)
      if (weights[i][a] != 0)
        x += weights[i][a] * host_positions.row(host_tets(tets[i], a)).transpose();
    out.row(i) = x.transpose();
  }
  return out;
}

MeshEmbedding embed_points(const mesh::TetMesh& host, ConstRef<Positions> points, double tolerance,
    const std::string& what) {
  if (!(tolerance >= 0) || !std::isfinite(tolerance))
    throw InputError("tolerance", "must be a finite distance >= 0, got " + to_text(tolerance));
  const TetGrid grid(host, tolerance);
  const Positions& rest = host.rest_positions();
  const Tets& tets = host.tets();
  MeshEmbedding out;
  out.tets.resize(points.rows());
  out.weights.resize(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Vec3 x = points.row(i).transpose();
    int best = -1;
    Location best_location { Eigen::Vector4d::Zero(), std::numeric_limits<double>::infinity() };
    const auto [begin, end] = grid.candidates(x);
    for (const int* e = begin; e != end; ++e) {
      Eigen::Matrix<double, 3, 4> p;
      for (int a = 0; a < 4; ++a)
        p.col(a) = rest.row(tets(*e, a)).transpose();
      const Location l = locate(p, x);
      if (l.outside < best_location.outside) {
        best = *e;
        best_location = l;
        if (l.outside <= 0)
          break; // inside (or on) this tet
      }
    }
    if (best < 0 || !(best_location.outside <= tolerance)) {
      throw InputError(what + " " + std::to_string(i),
          "at (" + to_text(x[0]) + ", " + to_text(x[1]) + ", " + to_text(x[2]) + ") lies "
              + (best < 0 ? std::string("outside the mesh's bounding box")
                          : to_text(best_location.outside) + " m outside the mesh")
              + " (tolerance " + to_text(tolerance) + " m)");
    }
    Eigen::Vector4d w = best_location.weights;
    for (int a = 0; a < 4; ++a)
      if (std::abs(w[a]) <= 1e-12)
        w[a] = 0;
    w /= w.sum();
    out.tets[i] = best;
    out.weights[i] = w;
    out.largest_outside = std::max(out.largest_outside, std::max(0.0, best_location.outside));
  }
  return out;
}

} // namespace elastolearn::observe
