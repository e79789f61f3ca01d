#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/observe/observation.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace elastolearn::observe {

namespace {

const std::string k_ids = "/observed/vertex_ids";
const std::string k_positions = "/observed/positions";
const std::string k_valid = "/observed/valid";

} // namespace

long Observation::num_valid() const {
  if (valid.size() == 0)
    return static_cast<long>(num_frames()) * num_observed();
  return static_cast<long>((valid != 0).count());
}

Observation Observation::frame_range(int first, int last) const {
  if (first < 0 || last < first || last >= num_frames())
    throw InputError("observation",
        "frames " + std::to_string(first) + ".." + std::to_string(last) + " are not within 0.."
            + std::to_string(num_frames() - 1));
  Observation out;
  out.vertex_ids = vertex_ids;
  out.dt = dt;
  out.start_time = start_time + first * dt;
  out.positions.assign(positions.begin() + first, positions.begin() + last + 1);
  if (valid.size() != 0)
    out.valid = valid.middleRows(first, last - first + 1);
  return out;
}

void Observation::validate(const std::string& source) const {
  const auto where = [&](const std::string& field) { return source + ": " + field; };
  const Eigen::Index k = static_cast<Eigen::Index>(vertex_ids.size());
  if (k == 0)
    throw InputError(where(k_ids), "no observed vertices");
  for (Eigen::Index j = 0; j < k; ++j) {
    if (vertex_ids[j] < 0) {
      throw InputError(where(k_ids),
          "vertex id " + std::to_string(vertex_ids[j]) + " (entry " + std::to_string(j)
              + ") is negative");
    }
  }
  std::vector<std::pair<int, Eigen::Index>> sorted(vertex_ids.size());
  for (Eigen::Index j = 0; j < k; ++j)
    sorted[j] = { vertex_ids[j], j };
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t j = 1; j < sorted.size(); ++j) {
    if (sorted[j].first == sorted[j - 1].first) {
      throw InputError(where(k_ids),
          "vertex id " + std::to_string(sorted[j].first) + " appears twice (entries "
              + std::to_string(sorted[j - 1].second) + " and " + std::to_string(sorted[j].second)
              + ")");
    }
  }
  if (positions.empty())
    throw InputError(where(k_positions), "no frames");
  if (valid.size() != 0) {
    if (valid.rows() != num_frames() || valid.cols() != k) {
      throw InputError(where(k_valid),
          "has shape (" + std::to_string(valid.rows()) + ", " + std::to_string(valid.cols())
              + "), expected (" + std::to_string(num_frames()) + ", " + std::to_string(k)
              + "): one entry per frame and observed vertex");
    }
    for (Eigen::Index t = 0; t < valid.rows(); ++t)
      for (Eigen::Index j = 0; j < k; ++j)
        if (valid(t, j) > 1) {
          throw InputError(where(k_valid),
              "frame " + std::to_string(t) + ": value " + std::to_string(int(valid(t, j)))
                  + " for vertex " + std::to_string(vertex_ids[j])
                  + " (expected 1 = seen or 0 = lost)");
        }
    if (num_valid() == 0)
      throw InputError(where(k_valid), "every entry is 0: no vertex was seen in any frame");
  }
  for (std::size_t t = 0; t < positions.size(); ++t) {
    const Positions& x = positions[t];
    if (x.rows() != k) {
      throw InputError(where(k_positions),
          "frame " + std::to_string(t) + " has " + std::to_string(x.rows())
              + " rows, expected one per observed vertex (" + std::to_string(k) + ")");
    }
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      if (!std::isfinite(x.data()[i]) && is_valid(static_cast<int>(t), static_cast<int>(i / 3))) {
        throw InputError(where(k_positions),
            "frame " + std::to_string(t) + ": non-finite value " + to_text_exact(x.data()[i])
                + " for vertex " + std::to_string(vertex_ids[i / 3]) + " (component "
                + std::to_string(i % 3) + ")"
                + (valid.size() != 0 ? ", which /observed/valid marks as seen" : ""));
      }
    }
  }
  if (!std::isfinite(dt) || dt <= 0)
    throw InputError(
        where("dt"), "time step must be positive and finite, got " + to_text_exact(dt));
  if (!std::isfinite(start_time))
    throw InputError(where("/time"), "non-finite start time " + to_text_exact(start_time));
}

void Observation::validate(
    int num_vertices, int expected_frames, double expected_dt, const std::string& source) const {
  validate(source);
  for (std::size_t j = 0; j < vertex_ids.size(); ++j) {
    if (vertex_ids[j] >= num_vertices) {
      throw InputError(source + ": " + k_ids,
          "vertex id " + std::to_string(vertex_ids[j]) + " (entry " + std::to_string(j)
              + ") is out of range [0, " + std::to_string(num_vertices) + ") of the mesh");
    }
  }
  if (expected_frames >= 0 && num_frames() != expected_frames) {
    throw InputError(source + ": " + k_positions,
        "has " + std::to_string(num_frames()) + " frames, the scene expects "
            + std::to_string(expected_frames));
  }
  if (expected_dt > 0 && std::abs(dt - expected_dt) > 1e-9 * expected_dt) {
    throw InputError(source + ": dt",
        "observation time step " + to_text_exact(dt) + " s does not match the scene's "
            + to_text_exact(expected_dt) + " s");
  }
}

std::string describe_lost_entries(const Observation& observed) {
  if (!observed.has_lost_entries())
    return "";
  const long total = static_cast<long>(observed.num_frames()) * observed.num_observed();
  const long lost = total - observed.num_valid();
  char text[96];
  std::snprintf(text, sizeof text, "%ld of %ld vertex-frames lost (%.1f %%)", lost, total,
      100.0 * static_cast<double>(lost) / static_cast<double>(total));
  return text;
}

double uniform_time_step(const std::vector<double>& time, const std::string& source) {
  if (time.size() < 2) {
    throw InputError(
        source, "cannot derive a time step from " + std::to_string(time.size()) + " frame(s)");
  }
  const double dt = time[1] - time[0];
  if (!std::isfinite(dt) || dt <= 0)
    throw InputError(
        source, "times do not increase: " + to_text_exact(time[0]) + ", " + to_text_exact(time[1]));
  for (std::size_t t = 2; t < time.size(); ++t) {
    const double step = time[t] - time[t - 1];
    if (!(std::abs(step - dt) <= 1e-6 * dt)) {
      throw InputError(source,
          "frames are not evenly spaced: interval " + std::to_string(t - 1) + " is "
              + to_text_exact(step) + " s, the first is " + to_text_exact(dt) + " s");
    }
  }
  return dt;
}

} // namespace elastolearn::observe
