#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/observe/visible_vertices.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace elastolearn::observe {

std::vector<int> farthest_point_sample(
    ConstRef<Positions> points, const std::vector<int>& candidates, int count, std::uint64_t seed) {
  const int n = static_cast<int>(candidates.size());
  if (count < 1 || count > n) {
    throw InputError("farthest-point sampling",
        "cannot pick " + std::to_string(count) + " of " + std::to_string(n) + " candidates");
  }
  for (int c : candidates) {
    if (c < 0 || c >= points.rows()) {
      throw InputError("farthest-point sampling",
          "candidate " + std::to_string(c) + " is not a point index in [0, "
              + std::to_string(points.rows()) + ")");
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> first(0, n - 1);
  // distance[j]: squared distance from candidate j to the nearest chosen point (−1 once chosen).
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  std::vector<int> chosen;
  chosen.reserve(count);
  int next = first(rng);
  for (int step = 0; step < count; ++step) {
    chosen.push_back(candidates[next]);
    distance[next] = -1;
    const Vec3 p = points.row(candidates[next]).transpose();
    int best = -1;
    double best_distance = -1;
    for (int j = 0; j < n; ++j) {
      if (distance[j] < 0)
        continue;
      distance[j]
          = std::min(distance[j], (points.row(candidates[j]).transpose() - p).squaredNorm());
      if (distance[j] > best_distance) {
        best_distance = distance[j];
        best = j;
      }
    }
    next = best;
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

int visible_vertex_count(double fraction, int num_surface_vertices) {
  if (!(fraction > 0 && fraction <= 1))
    throw InputError("visible fraction", "must be in (0, 1], got " + to_text(fraction));
  const int count = static_cast<int>(std::lround(fraction * num_surface_vertices));
  return std::clamp(count, 1, std::max(1, num_surface_vertices));
}

std::vector<int> select_visible_vertices(
    const mesh::TetMesh& mesh, double fraction, std::uint64_t seed) {
  const std::vector<int>& surface = mesh.surface_vertices();
  const int count = visible_vertex_count(fraction, static_cast<int>(surface.size()));
  if (count == static_cast<int>(surface.size()))
    return surface; // already sorted; no sampling needed for "all"
  return farthest_point_sample(mesh.rest_positions(), surface, count, seed);
}

Observation observe_vertices(const std::vector<Positions>& frames, double dt,
    const std::vector<int>& ids, double noise_sigma, std::uint64_t seed, double start_time) {
  if (!std::isfinite(noise_sigma) || noise_sigma < 0)
    throw InputError("noise",
        "noise standard deviation must be finite and non-negative, got " + to_text(noise_sigma));
  if (frames.empty())
    throw InputError("trajectory", "no frames to observe");
  const Eigen::Index n = frames.front().rows();
  Observation obs;
  obs.vertex_ids = ids;
  obs.dt = dt;
  obs.start_time = start_time;
  for (std::size_t j = 0; j < ids.size(); ++j) {
    if (ids[j] < 0 || ids[j] >= n) {
      throw InputError("observed vertices",
          "vertex id " + std::to_string(ids[j]) + " (entry " + std::to_string(j)
              + ") is out of range [0, " + std::to_string(n) + ")");
    }
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma > 0 ? noise_sigma : 1.0);
  const Eigen::Index k = static_cast<Eigen::Index>(ids.size());
  obs.positions.reserve(frames.size());
  for (std::size_t t = 0; t < frames.size(); ++t) {
    if (frames[t].rows() != n) {
      throw InputError("trajectory",
          "frame " + std::to_string(t) + " has " + std::to_string(frames[t].rows())
              + " vertices, frame 0 has " + std::to_string(n));
    }
    Positions x(k, 3);
    for (Eigen::Index j = 0; j < k; ++j) {
      x.row(j) = frames[t].row(ids[j]);
      if (noise_sigma > 0) {
        for (int c = 0; c < 3; ++c)
          x(j, c) += noise(rng);
      }
    }
    obs.positions.push_back(std::move(x));
  }
  obs.validate(static_cast<int>(n), static_cast<int>(frames.size()), dt, "observation");
  return obs;
}

} // namespace elastolearn::observe
