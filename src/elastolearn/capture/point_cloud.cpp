#include <elastolearn/capture/point_cloud.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::capture {

namespace {

const std::string k_points = "/clouds/points";
const std::string k_offsets = "/clouds/offsets";
const std::string k_normals = "/clouds/normals";
const std::string k_confidence = "/clouds/confidence";

/// "frame t, point j" of global point row i (offsets already checked).
std::string point_name(const std::vector<Eigen::Index>& offsets, Eigen::Index i) {
  const auto it = std::upper_bound(offsets.begin(), offsets.end(), i);
  const auto t = static_cast<Eigen::Index>(it - offsets.begin()) - 1;
  return "frame " + std::to_string(t) + ", point " + std::to_string(i - offsets[t]);
}

} // namespace

CloudFrame PointCloudSequence::frame(int t) const {
  CloudFrame f;
  const Eigen::Index begin = offsets[t], count = frame_size(t);
  f.points = points.middleRows(begin, count);
  if (has_normals())
    f.normals = normals.middleRows(begin, count);
  if (has_confidence())
    f.confidence = confidence.segment(begin, count);
  return f;
}

void PointCloudSequence::append(const CloudFrame& frame, const std::string& source) {
  const Eigen::Index n = frame.points.rows();
  if (frame.normals.rows() != 0 && frame.normals.rows() != n)
    throw InputError(source,
        "has " + std::to_string(frame.normals.rows()) + " normals for " + std::to_string(n)
            + " points");
  if (frame.confidence.size() != 0 && frame.confidence.size() != n)
    throw InputError(source,
        "has " + std::to_string(frame.confidence.size()) + " confidence values for "
            + std::to_string(n) + " points");
  const bool decided = num_points() > 0;
  if (n > 0) {
    const bool frame_normals = frame.normals.rows() > 0;
    const bool frame_confidence = frame.confidence.size() > 0;
    if (decided && frame_normals != has_normals())
      throw InputError(source,
          std::string(frame_normals ? "has" : "has no") + " normals, but the frames before "
              + (has_normals() ? "have" : "have none"));
    if (decided && frame_confidence != has_confidence())
      throw InputError(source,
          std::string(frame_confidence ? "has" : "has no")
              + " confidence values, but the frames before "
              + (has_confidence() ? "have" : "have none"));
    const Eigen::Index old = num_points();
    points.conservativeResize(old + n, 3);
    points.bottomRows(n) = frame.points;
    if (frame_normals) {
      normals.conservativeResize(old + n, 3);
      normals.bottomRows(n) = frame.normals;
    }
    if (frame_confidence) {
      confidence.conservativeResize(old + n);
      confidence.tail(n) = frame.confidence;
    }
  }
  offsets.push_back(num_points());
}

void PointCloudSequence::validate(const std::string& source) const {
  const auto where = [&](const std::string& field) { return source + ": " + field; };
  if (offsets.size() < 2)
    throw InputError(where(k_offsets), "no frames (offsets need T + 1 ≥ 2 entries)");
  if (offsets.front() != 0)
    throw InputError(where(k_offsets), "must start at 0, got " + std::to_string(offsets.front()));
  for (std::size_t t = 1; t < offsets.size(); ++t) {
    if (offsets[t] < offsets[t - 1])
      throw InputError(where(k_offsets),
          "entry " + std::to_string(t) + " (" + std::to_string(offsets[t]) + ") is less than entry "
              + std::to_string(t - 1) + " (" + std::to_string(offsets[t - 1])
              + "): offsets must not decrease");
  }
  if (offsets.back() != num_points())
    throw InputError(where(k_offsets),
        "ends at " + std::to_string(offsets.back()) + " but " + k_points + " has "
            + std::to_string(num_points()) + " points");
  for (Eigen::Index i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points.data()[i]))
      throw InputError(where(k_points),
          point_name(offsets, i / 3) + ": non-finite coordinate " + to_text_exact(points.data()[i])
              + " (component " + std::to_string(i % 3) + ")");
  }
  if (has_normals()) {
    if (normals.rows() != num_points())
      throw InputError(where(k_normals),
          "has " + std::to_string(normals.rows()) + " rows, " + k_points + " has "
              + std::to_string(num_points()));
    for (Eigen::Index i = 0; i < normals.rows(); ++i) {
      const double length = normals.row(i).norm();
      if (!(std::abs(length - 1) <= k_normal_length_tolerance))
        throw InputError(where(k_normals),
            point_name(offsets, i) + ": not a unit vector (length " + to_text(length) + ")");
    }
  }
  if (has_confidence()) {
    if (confidence.size() != num_points())
      throw InputError(where(k_confidence),
          "has " + std::to_string(confidence.size()) + " values, " + k_points + " has "
              + std::to_string(num_points()) + " points");
    for (Eigen::Index i = 0; i < confidence.size(); ++i) {
      if (!(confidence[i] >= 0 && confidence[i] <= 1))
        throw InputError(where(k_confidence),
            point_name(offsets, i) + ": " + to_text_exact(confidence[i]) + " is not in [0, 1]");
    }
  }
  if (!std::isfinite(dt) || dt <= 0)
    throw InputError(where("dt"), "must be positive and finite, got " + to_text_exact(dt));
  if (!std::isfinite(start_time))
    throw InputError(where("/time"), "non-finite start time " + to_text_exact(start_time));
}

} // namespace elastolearn::capture
