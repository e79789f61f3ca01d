#include <elastolearn/capture/point_cloud.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <cmath>

namespace elastolearn::capture {

namespace {

const std::string k_points = "/clouds/points";
const std::string k_offsets = "/clouds/offsets";
const std::string k_normals = "/clouds/normals";
const std::string k_confidence = "/clouds/confidence";

/// The checks of CloudFrame::validate on views of one frame.
void check_frame(ConstRef<Positions> points, ConstRef<Positions> normals,
    const Eigen::Ref<const VecX>& confidence, const std::string& source, int frame) {
  const auto where = [&](const std::string& field) { return source + ": " + field; };
  const auto point = [&](Eigen::Index j) {
    return "frame " + std::to_string(frame) + ", point " + std::to_string(j);
  };
  const Eigen::Index n = points.rows();
  if (normals.rows() != 0 && normals.rows() != n)
    throw InputError(where(k_normals),
        "frame " + std::to_string(frame) + " has " + std::to_string(normals.rows())
            + " normals for " + std::to_string(n) + " points");
  if (confidence.size() != 0 && confidence.size() != n)
    throw InputError(where(k_confidence),
        "frame " + std::to_string(frame) + " has " + std::to_string(confidence.size())
            + " confidence values for " + std::to_string(n) + " points");
  for (Eigen::Index j = 0; j < n; ++j)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(points(j, c)))
        throw InputError(where(k_points),
            point(j) + ": non-finite coordinate " + to_text_exact(points(j, c)) + " (component "
                + std::to_string(c) + ")");
  for (Eigen::Index j = 0; j < normals.rows(); ++j) {
    const double length = normals.row(j).norm();
    if (!(std::abs(length - 1) <= k_normal_length_tolerance))
      throw InputError(
          where(k_normals), point(j) + ": not a unit vector (length " + to_text(length) + ")");
  }
  for (Eigen::Index j = 0; j < confidence.size(); ++j)
    if (!(confidence[j] >= 0 && confidence[j] <= 1))
      throw InputError(where(k_confidence),
          point(j) + ": " + to_text_exact(confidence[j]) + " is not in [0, 1]");
}

} // namespace

void CloudFrame::validate(const std::string& source, int frame) const {
  check_frame(points, normals, confidence, source, frame);
}

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

void FrameLayout::check(const CloudFrame& frame, const std::string& source) {
  if (frame.points.rows() == 0)
    return;
  const bool normals = frame.normals.rows() > 0, confidence = frame.confidence.size() > 0;
  if (!m_decided) {
    m_decided = true;
    m_normals = normals;
    m_confidence = confidence;
    return;
  }
  if (normals != m_normals)
    throw InputError(source,
        std::string(normals ? "has" : "has no") + " normals, but the frames before "
            + (m_normals ? "have them" : "have none"));
  if (confidence != m_confidence)
    throw InputError(source,
        std::string(confidence ? "has" : "has no") + " confidence values, but the frames before "
            + (m_confidence ? "have them" : "have none"));
}

PointCloudSequence PointCloudSequence::from_frames(const std::vector<CloudFrame>& frames, double dt,
    double start_time, const std::string& source) {
  FrameLayout layout;
  Eigen::Index total = 0;
  for (std::size_t t = 0; t < frames.size(); ++t) {
    const std::string where = source + ": frame " + std::to_string(t);
    frames[t].validate(source, static_cast<int>(t));
    layout.check(frames[t], where);
    total += frames[t].points.rows();
  }
  PointCloudSequence s;
  s.dt = dt;
  s.start_time = start_time;
  s.points.resize(total, 3);
  if (layout.normals())
    s.normals.resize(total, 3);
  if (layout.confidence())
    s.confidence.resize(total);
  s.offsets.assign(1, 0);
  for (const CloudFrame& f : frames) {
    const Eigen::Index begin = s.offsets.back(), n = f.points.rows();
    s.points.middleRows(begin, n) = f.points;
    if (n > 0 && layout.normals())
      s.normals.middleRows(begin, n) = f.normals;
    if (n > 0 && layout.confidence())
      s.confidence.segment(begin, n) = f.confidence;
    s.offsets.push_back(begin + n);
  }
  s.validate(source);
  return s;
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
  if (has_normals() && normals.rows() != num_points())
    throw InputError(where(k_normals),
        "has " + std::to_string(normals.rows()) + " rows, " + k_points + " has "
            + std::to_string(num_points()));
  if (has_confidence() && confidence.size() != num_points())
    throw InputError(where(k_confidence),
        "has " + std::to_string(confidence.size()) + " values, " + k_points + " has "
            + std::to_string(num_points()) + " points");
  for (int t = 0; t < num_frames(); ++t) {
    const Eigen::Index begin = offsets[t], count = frame_size(t);
    check_frame(points.middleRows(begin, count),
        has_normals() ? normals.middleRows(begin, count) : normals.middleRows(0, 0),
        has_confidence() ? confidence.segment(begin, count) : confidence.segment(0, 0), source, t);
  }
  if (!std::isfinite(dt) || dt <= 0)
    throw InputError(where("dt"), "must be positive and finite, got " + to_text_exact(dt));
  if (!std::isfinite(start_time))
    throw InputError(where("/time"), "non-finite start time " + to_text_exact(start_time));
}

} // namespace elastolearn::capture
