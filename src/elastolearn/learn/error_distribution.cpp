#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/error_distribution.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace elastolearn::learn {

namespace {

void check_frames(const std::vector<VecX>& frames, Eigen::Index size, const char* name) {
  if (frames.empty())
    throw InputError("vertex_errors", std::string(name) + " has no frames");
  for (std::size_t t = 0; t < frames.size(); ++t) {
    if (frames[t].size() != size) {
      throw InputError("vertex_errors",
          std::string(name) + " frame " + std::to_string(t) + " has "
              + std::to_string(frames[t].size()) + " coordinates, expected "
              + std::to_string(size));
    }
  }
}

void check_vertices(const std::vector<int>& vertices, int n) {
  for (int v : vertices) {
    if (v < 0 || v >= n) {
      throw InputError("vertex_errors",
          "vertex " + std::to_string(v) + " is out of range [0, " + std::to_string(n) + ")");
    }
  }
}

} // namespace

Eigen::MatrixXd vertex_errors(
    const std::vector<VecX>& a, const std::vector<VecX>& b, const std::vector<int>& vertices) {
  if (a.empty() || b.empty())
    throw InputError("vertex_errors", "a trajectory has no frames");
  const Eigen::Index size = a.front().size();
  if (size % 3 != 0) {
    throw InputError(
        "vertex_errors", "frame size " + std::to_string(size) + " is not a multiple of 3");
  }
  check_frames(a, size, "the first trajectory");
  check_frames(b, size, "the second trajectory");
  const int n = static_cast<int>(size / 3);
  check_vertices(vertices, n);
  const auto frames = static_cast<Eigen::Index>(std::min(a.size(), b.size()));
  const int count = vertices.empty() ? n : static_cast<int>(vertices.size());
  Eigen::MatrixXd e(frames, count);
  for (Eigen::Index t = 0; t < frames; ++t) {
    for (int j = 0; j < count; ++j) {
      const int v = vertices.empty() ? j : vertices[j];
      e(t, j) = (a[t].segment<3>(3 * v) - b[t].segment<3>(3 * v)).norm();
    }
  }
  return e;
}

Eigen::MatrixXd vertex_errors(const std::vector<VecX>& frames, const observe::Observation& obs) {
  if (frames.empty() || obs.positions.empty())
    throw InputError("vertex_errors", "no frames to compare");
  check_frames(frames, frames.front().size(), "the simulation");
  const int n = static_cast<int>(frames.front().size() / 3);
  check_vertices(obs.vertex_ids, n);
  const auto count = static_cast<Eigen::Index>(obs.vertex_ids.size());
  const auto num_frames = static_cast<Eigen::Index>(std::min(frames.size(), obs.positions.size()));
  Eigen::MatrixXd e(num_frames, count);
  for (Eigen::Index t = 0; t < num_frames; ++t) {
    const Positions& observed = obs.positions[t];
    if (observed.rows() != count) {
      throw InputError("vertex_errors",
          "observation frame " + std::to_string(t) + " has " + std::to_string(observed.rows())
              + " rows, expected " + std::to_string(count));
    }
    for (Eigen::Index j = 0; j < count; ++j) {
      const int v = obs.vertex_ids[j];
      e(t, j) = (frames[t].segment<3>(3 * v) - observed.row(j).transpose()).norm();
    }
  }
  return e;
}

FrameErrors frame_errors(const Eigen::MatrixXd& errors) {
  FrameErrors out;
  out.max.reserve(errors.rows());
  out.rms.reserve(errors.rows());
  for (Eigen::Index t = 0; t < errors.rows(); ++t) {
    const auto row = errors.row(t);
    out.max.push_back(row.size() > 0 ? row.maxCoeff() : 0.0);
    out.rms.push_back(row.size() > 0 ? std::sqrt(row.squaredNorm() / double(row.size())) : 0.0);
  }
  return out;
}

std::vector<double> log_bin_edges(double low, double high, int bins) {
  if (!(low > 0) || !(high > low) || !std::isfinite(high) || bins < 1) {
    throw InputError("error histogram",
        "needs 0 < low < high and at least one bin, got low " + std::to_string(low) + ", high "
            + std::to_string(high) + ", " + std::to_string(bins) + " bins");
  }
  std::vector<double> edges(static_cast<std::size_t>(bins) + 1);
  const double step = std::log(high / low) / bins;
  for (int i = 0; i <= bins; ++i)
    edges[static_cast<std::size_t>(i)] = low * std::exp(step * i);
  edges.back() = high; // exactly, whatever exp rounds to
  return edges;
}

std::vector<long> histogram_counts(std::span<const double> values, std::span<const double> edges) {
  if (edges.size() < 2)
    throw InputError("error histogram", "needs at least two bin edges");
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (!(edges[i] > edges[i - 1]))
      throw InputError("error histogram", "bin edges must increase");
  }
  std::vector<long> counts(edges.size() - 1, 0);
  for (double v : values) {
    // The first edge greater than v closes v's bin; clamp to the first and last bins.
    const auto upper = std::upper_bound(edges.begin(), edges.end(), v);
    const auto bin = std::clamp<std::ptrdiff_t>(
        upper - edges.begin() - 1, 0, static_cast<std::ptrdiff_t>(counts.size()) - 1);
    ++counts[static_cast<std::size_t>(bin)];
  }
  return counts;
}

} // namespace elastolearn::learn
