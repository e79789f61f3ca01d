#pragma once
/// \file Observations (paper 000 §3, §5.1): the positions of a subset of the mesh's vertices at
/// every frame of a motion — the sparse surface trajectories s_i of Eq. (4) that the learning
/// loop fits. On disk they are HDF5 files (io/observation_file.hpp, docs/observations.md).
#include <elastolearn/core/types.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace elastolearn::observe {

/// Which entries of an observation were seen: T × k (frame-major), 1 = seen, 0 = lost.
using ValidityMask = Eigen::Array<std::uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Observed positions of k mesh vertices over T frames spaced dt apart.
///
/// Row j of every frame belongs to vertex `vertex_ids[j]`; frame t was taken at time
/// `start_time + t·dt`. Field names in error messages follow the file layout
/// ("/observed/vertex_ids", "/observed/positions", "/observed/valid", "dt").
///
/// Lost markers: where `valid(t, j)` is 0, point j was not seen in frame t and its stored
/// position means nothing (it may be anything, NaN included). Every consumer ignores such
/// entries; none reads their positions. An empty mask means every entry was seen.
struct Observation {
  std::vector<int> vertex_ids; ///< k distinct mesh vertex indices (any order)
  std::vector<Positions> positions; ///< T frames, each k×3 [m]
  ValidityMask valid; ///< T × k of 0/1, or empty (all seen)
  double dt = 0; ///< time between frames [s], > 0
  double start_time = 0; ///< time of frame 0 [s]

  int num_observed() const { return static_cast<int>(vertex_ids.size()); }
  int num_frames() const { return static_cast<int>(positions.size()); }
  /// True if point j was seen in frame t.
  bool is_valid(int t, int j) const { return valid.size() == 0 || valid(t, j) != 0; }
  /// True if some entry is lost (the mask holds a 0).
  bool has_lost_entries() const { return valid.size() != 0 && (valid == 0).any(); }
  /// Number of seen (frame, point) entries.
  long num_valid() const;
  /// Frames first..last (inclusive) with their mask; frame `first` becomes frame 0.
  /// Throws InputError unless 0 ≤ first ≤ last < T.
  Observation frame_range(int first, int last) const;

  /// Check internal consistency: k ≥ 1, T ≥ 1, ids ≥ 0 and distinct, every frame k×3, the mask
  /// empty or T × k of 0/1 with at least one 1, every seen position finite (lost ones may be
  /// anything), dt finite and positive, start_time finite. A point never seen is allowed: it is
  /// ignored like every lost entry.
  /// Throws InputError("<source>: <field>", what is wrong and the offending value).
  void validate(const std::string& source) const;

  /// validate(source), then check against the scene it is used with: ids < num_vertices,
  /// T == expected_frames (skipped if expected_frames < 0), and |dt − expected_dt| ≤ 1e-9·dt
  /// (skipped if expected_dt ≤ 0). Throws InputError naming `source` and the field.
  void validate(
      int num_vertices, int expected_frames, double expected_dt, const std::string& source) const;
};

/// "7717 of 39396 vertex-frames lost (19.6 %)" for an observation with lost entries, "" for one
/// without (for the commands' summaries).
std::string describe_lost_entries(const Observation& observed);

/// The constant spacing of `time` (T ≥ 2 increasing times [s]): time[1] − time[0], after
/// checking that every interval matches it within 1e-6 relative (recorded times are sums of
/// steps, so they carry rounding). Throws InputError(source, ...) for T < 2 or uneven spacing.
double uniform_time_step(const std::vector<double>& time, const std::string& source);

} // namespace elastolearn::observe
