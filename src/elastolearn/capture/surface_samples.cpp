#include <elastolearn/capture/surface_samples.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace elastolearn::capture {

void SurfaceSamples::positions(ConstRef<Positions> x, Positions& out) const {
  out.resize(vertices.rows(), 3);
  for (Eigen::Index k = 0; k < vertices.rows(); ++k)
    out.row(k) = weights(k, 0) * x.row(vertices(k, 0)) + weights(k, 1) * x.row(vertices(k, 1))
        + weights(k, 2) * x.row(vertices(k, 2));
}

Positions SurfaceSamples::positions(ConstRef<Positions> x) const {
  Positions out;
  positions(x, out);
  return out;
}

void SurfaceSamples::scatter(ConstRef<Positions> per_sample, Positions& per_vertex) const {
  for (Eigen::Index k = 0; k < vertices.rows(); ++k)
    for (int j = 0; j < 3; ++j)
      per_vertex.row(vertices(k, j)) += weights(k, j) * per_sample.row(k);
}

Positions sample_normals(const SurfaceSamples& samples, const Faces& faces, ConstRef<Positions> x) {
  Positions vertex_normals = Positions::Zero(x.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::RowVector3d a = x.row(faces(f, 0));
    const Eigen::RowVector3d n = (x.row(faces(f, 1)) - a).cross(x.row(faces(f, 2)) - a); // 2·area
    for (int j = 0; j < 3; ++j)
      vertex_normals.row(faces(f, j)) += n;
  }
  Positions out = samples.positions(vertex_normals);
  for (Eigen::Index k = 0; k < out.rows(); ++k) {
    const double length = out.row(k).norm();
    out.row(k) = length > 0 ? Eigen::RowVector3d(out.row(k) / length) : Eigen::RowVector3d::Zero();
  }
  return out;
}

SurfaceSamples sample_surface(const Faces& faces, int subdivision) {
  const int s = subdivision;
  if (s < 1 || s > 64)
    throw InputError("surface samples", "subdivision must be in [1, 64], got " + std::to_string(s));
  if (faces.size() > 0 && faces.minCoeff() < 0)
    throw InputError("surface samples", "negative vertex index in the faces");
  std::vector<int> used(faces.data(), faces.data() + faces.size());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::vector<std::pair<int, int>> edges;
  if (s > 1) {
    edges.reserve(static_cast<std::size_t>(3 * faces.rows()));
    for (Eigen::Index f = 0; f < faces.rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const int a = faces(f, c), b = faces(f, (c + 1) % 3);
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  }
  const Eigen::Index per_edge = s - 1;
  const Eigen::Index per_face = static_cast<Eigen::Index>(s - 1) * (s - 2) / 2;
  const Eigen::Index count = static_cast<Eigen::Index>(used.size())
      + per_edge * static_cast<Eigen::Index>(edges.size()) + per_face * faces.rows();
  SurfaceSamples out;
  out.vertices.resize(count, 3);
  out.weights.resize(count, 3);
  Eigen::Index k = 0;
  for (int v : used) {
    out.vertices.row(k) << v, v, v;
    out.weights.row(k++) << 1, 0, 0;
  }
  for (const auto& [a, b] : edges)
    for (int i = 1; i < s; ++i) {
      out.vertices.row(k) << a, b, b;
      out.weights.row(k++) << double(s - i) / s, double(i) / s, 0;
    }
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int i = 1; i < s; ++i)
      for (int j = 1; i + j < s; ++j) {
        out.vertices.row(k) = faces.row(f);
        out.weights.row(k++) << double(s - i - j) / s, double(i) / s, double(j) / s;
      }
  ELASTOLEARN_CHECK(k == count, "sample_surface: sample count");
  return out;
}

int subdivision_for_spacing(ConstRef<Positions> x, const Faces& faces, double spacing) {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw InputError("surface samples", "spacing must be positive, got " + to_text(spacing));
  double longest = 0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      longest = std::max(longest, (x.row(faces(f, c)) - x.row(faces(f, (c + 1) % 3))).norm());
  const double s = std::ceil(longest / spacing);
  return static_cast<int>(std::clamp(s, 1.0, 64.0));
}

} // namespace elastolearn::capture
