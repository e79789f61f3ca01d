#pragma once
/// \file Point-cloud sequences (paper 000 §5.3): one unordered set of scanned surface points per
/// frame, as a depth camera or a scanning tool records them — the c_n of Eq. (9). Frames may
/// hold different numbers of points, and none: an empty frame constrains nothing. On disk:
/// io/cloud_file.hpp (docs/file_formats.md, "Point clouds").
#include <elastolearn/core/types.hpp>

#include <string>
#include <vector>

namespace elastolearn::capture {

/// The points of one frame, with optional per-point normals and confidence.
struct CloudFrame {
  Positions points; ///< N×3 [m]
  Positions normals; ///< N×3 unit vectors, or 0 rows when the frame has none
  VecX confidence; ///< N values in [0, 1], or empty when the frame has none

  /// Check sizes (normals N×3 or none, confidence N or none), finite points, unit normals
  /// (k_normal_length_tolerance) and confidence in [0, 1]. Errors are
  /// InputError("<source>: /clouds/<field>", "frame <frame>, point <j>: …").
  void validate(const std::string& source, int frame) const;
};

/// T frames of points stored back to back: frame t is rows offsets[t] … offsets[t+1]−1 of
/// `points` (and of `normals`, `confidence` when present); frame t was taken at
/// start_time + t·dt. Field names in errors follow the file layout ("/clouds/points",
/// "/clouds/offsets", "dt").
struct PointCloudSequence {
  Positions points; ///< N×3 [m], all frames
  std::vector<Eigen::Index> offsets { 0 }; ///< T+1 non-decreasing, offsets[0] = 0, offsets[T] = N
  Positions normals; ///< N×3 unit vectors, or 0 rows (no normals)
  VecX confidence; ///< N values in [0, 1], or empty (no confidence)
  double dt = 0; ///< time between frames [s], > 0
  double start_time = 0; ///< time of frame 0 [s]

  int num_frames() const { return static_cast<int>(offsets.size()) - 1; }
  Eigen::Index num_points() const { return points.rows(); }
  Eigen::Index frame_size(int t) const { return offsets[t + 1] - offsets[t]; }
  bool has_normals() const { return normals.rows() > 0; }
  bool has_confidence() const { return confidence.size() > 0; }

  /// Frame t's points (a view into `points`), t in [0, num_frames()).
  auto frame_points(int t) const { return points.middleRows(offsets[t], frame_size(t)); }
  /// A copy of frame t with its normals and confidence.
  CloudFrame frame(int t) const;

  /// The sequence of `frames` (copied once), frame t taken at start_time + t·dt, checked with
  /// FrameLayout (errors name "<source>: frame t") and validate(source). Throws InputError.
  static PointCloudSequence from_frames(const std::vector<CloudFrame>& frames, double dt,
      double start_time, const std::string& source);

  /// Check consistency: T ≥ 1, offsets as documented, every point finite, normals (if any) N×3
  /// finite of length 1 within 1e-3, confidence (if any) N values in [0, 1], dt finite and
  /// positive, start_time finite. Throws InputError("<source>: <field>", what is wrong, the frame
  /// and point, and the offending value).
  void validate(const std::string& source) const;
};

/// Whether the frames of a sequence carry normals and confidence: the first frame with points
/// decides, and every later frame with points must agree (empty frames agree with anything).
class FrameLayout {
  public:
  /// Check `frame` (and let it decide, if it is the first with points). Throws
  /// InputError(source, "has normals, but the frames before have none") and the like.
  void check(const CloudFrame& frame, const std::string& source);
  bool normals() const { return m_normals; }
  bool confidence() const { return m_confidence; }

  private:
  bool m_decided = false;
  bool m_normals = false;
  bool m_confidence = false;
};

/// Length tolerance of a unit normal: |‖n‖ − 1| ≤ 1e-3 (float32 normals written by scanning tools
/// pass; colours or unnormalised vectors do not).
inline constexpr double k_normal_length_tolerance = 1e-3;

} // namespace elastolearn::capture
