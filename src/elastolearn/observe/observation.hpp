#pragma once
/// \file Observations (paper 000 §3, §5.1): the positions of a subset of the mesh's vertices at
/// every frame of a motion — the sparse surface trajectories s_i of Eq. (4) that the learning
/// loop fits. On disk they are HDF5 files (io/observation_file.hpp, docs/observations.md).
#include <elastolearn/core/types.hpp>

#include <string>
#include <vector>

namespace elastolearn::observe {

/// Observed positions of k mesh vertices over T frames spaced dt apart.
///
/// Row j of every frame belongs to vertex `vertex_ids[j]`; frame t was taken at time
/// `start_time + t·dt`. Field names in error messages follow the file layout
/// ("/observed/vertex_ids", "/observed/positions", "dt").
struct Observation {
  std::vector<int> vertex_ids; ///< k distinct mesh vertex indices (any order)
  std::vector<Positions> positions; ///< T frames, each k×3 [m]
  double dt = 0; ///< time between frames [s], > 0
  double start_time = 0; ///< time of frame 0 [s]

  int num_observed() const { return static_cast<int>(vertex_ids.size()); }
  int num_frames() const { return static_cast<int>(positions.size()); }

  /// Check internal consistency: k ≥ 1, T ≥ 1, ids ≥ 0 and distinct, every frame k×3 and
  /// finite, dt finite and positive, start_time finite.
  /// Throws InputError("<source>: <field>", what is wrong and the offending value).
  void validate(const std::string& source) const;

  /// validate(source), then check against the scene it is used with: ids < num_vertices,
  /// T == expected_frames (skipped if expected_frames < 0), and |dt − expected_dt| ≤ 1e-9·dt
  /// (skipped if expected_dt ≤ 0). Throws InputError naming `source` and the field.
  void validate(
      int num_vertices, int expected_frames, double expected_dt, const std::string& source) const;
};

/// The constant spacing of `time` (T ≥ 2 increasing times [s]): time[1] − time[0], after
/// checking that every interval matches it within 1e-6 relative (recorded times are sums of
/// steps, so they carry rounding). Throws InputError(source, ...) for T < 2 or uneven spacing.
double uniform_time_step(const std::vector<double>& time, const std::string& source);

} // namespace elastolearn::observe
