#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/trajectory_error.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace elastolearn::learn {

namespace {

/// Accumulates e over (frame, vertex) pairs.
class ErrorAccumulator {
  public:
  void add(double e, int frame, int vertex) {
    if (e > m_out.max || m_out.worst_frame < 0) {
      m_out.max = e;
      m_out.worst_frame = frame;
      m_out.worst_vertex = vertex;
    }
    m_sum += e;
    m_sum_squares += e * e;
    ++m_out.samples;
  }
  ErrorSummary summary() const {
    ErrorSummary out = m_out;
    if (out.samples > 0) {
      out.mean = m_sum / double(out.samples);
      out.rms = std::sqrt(m_sum_squares / double(out.samples));
    }
    return out;
  }

  private:
  ErrorSummary m_out;
  double m_sum = 0;
  double m_sum_squares = 0;
};

void check_frames(const std::vector<VecX>& frames, Eigen::Index size, const char* name) {
  if (frames.empty())
    throw InputError("position_error", std::string(name) + " has no frames");
  for (std::size_t t = 0; t < frames.size(); ++t) {
    if (frames[t].size() != size) {
      throw InputError("position_error",
          std::string(name) + " frame " + std::to_string(t) + " has "
              + std::to_string(frames[t].size()) + " coordinates, expected "
              + std::to_string(size));
    }
  }
}

} // namespace

ErrorSummary position_error(
    const std::vector<VecX>& a, const std::vector<VecX>& b, const std::vector<int>& vertices) {
  if (a.empty() || b.empty())
    throw InputError("position_error", "a trajectory has no frames");
  const Eigen::Index size = a.front().size();
  if (size % 3 != 0) {
    throw InputError(
        "position_error", "frame size " + std::to_string(size) + " is not a multiple of 3");
  }
  check_frames(a, size, "the first trajectory");
  check_frames(b, size, "the second trajectory");
  const int n = static_cast<int>(size / 3);
  for (int v : vertices) {
    if (v < 0 || v >= n) {
      throw InputError("position_error",
          "vertex " + std::to_string(v) + " is out of range [0, " + std::to_string(n) + ")");
    }
  }
  const int frames = static_cast<int>(std::min(a.size(), b.size()));
  const int count = vertices.empty() ? n : static_cast<int>(vertices.size());
  ErrorAccumulator acc;
  for (int t = 0; t < frames; ++t) {
    for (int j = 0; j < count; ++j) {
      const int v = vertices.empty() ? j : vertices[j];
      acc.add((a[t].segment<3>(3 * v) - b[t].segment<3>(3 * v)).norm(), t, v);
    }
  }
  return acc.summary();
}

ErrorSummary observation_error(const std::vector<VecX>& frames, const observe::Observation& obs) {
  if (frames.empty() || obs.positions.empty())
    throw InputError("observation_error", "no frames to compare");
  const Eigen::Index size = frames.front().size();
  check_frames(frames, size, "the simulation");
  const int n = static_cast<int>(size / 3);
  for (int v : obs.vertex_ids) {
    if (v < 0 || v >= n) {
      throw InputError("observation_error",
          "observed vertex " + std::to_string(v) + " is out of range [0, " + std::to_string(n)
              + ") of the simulated mesh");
    }
  }
  const int count = obs.num_observed();
  const int num_frames
      = static_cast<int>(std::min<std::size_t>(frames.size(), obs.positions.size()));
  ErrorAccumulator acc;
  for (int t = 0; t < num_frames; ++t) {
    const Positions& observed = obs.positions[t];
    if (observed.rows() != count) {
      throw InputError("observation_error",
          "observation frame " + std::to_string(t) + " has " + std::to_string(observed.rows())
              + " rows, expected " + std::to_string(count));
    }
    for (int j = 0; j < count; ++j) {
      if (!obs.is_valid(t, j))
        continue; // a lost entry: its position means nothing
      const int v = obs.vertex_ids[j];
      acc.add((frames[t].segment<3>(3 * v) - observed.row(j).transpose()).norm(), t, v);
    }
  }
  return acc.summary();
}

ErrorSummary combined_error(std::span<const ErrorSummary> parts) {
  if (parts.empty())
    return {};
  ErrorSummary out = parts.front();
  for (const ErrorSummary& part : parts.subspan(1)) {
    if (part.samples == 0)
      continue;
    if (part.max > out.max || out.worst_frame < 0) {
      out.max = part.max;
      out.worst_frame = part.worst_frame;
      out.worst_vertex = part.worst_vertex;
    }
    const double a = double(out.samples), b = double(part.samples);
    out.mean = (a * out.mean + b * part.mean) / (a + b);
    out.rms = std::sqrt((a * out.rms * out.rms + b * part.rms * part.rms) / (a + b));
    out.samples += part.samples;
  }
  return out;
}

ErrorSummary as_percent_of(const ErrorSummary& error, double length) {
  if (!(std::isfinite(length) && length > 0)) {
    throw InputError(
        "as_percent_of", "length must be positive and finite, got " + std::to_string(length));
  }
  ErrorSummary out = error;
  const double s = 100.0 / length;
  out.max *= s;
  out.mean *= s;
  out.rms *= s;
  return out;
}

} // namespace elastolearn::learn
