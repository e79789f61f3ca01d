#pragma once
/// \file Vertex position errors between trajectories: the err_L of paper 000's Table 1 (the
/// maximum vertex position error over a trajectory, as a percentage of the rest shape's
/// bounding-box diagonal) and the mean and RMS errors beside it.
#include <elastolearn/core/types.hpp>
#include <elastolearn/observe/observation.hpp>

#include <span>
#include <vector>

namespace elastolearn::learn {

/// Statistics of the vertex position error e = ‖a − b‖ over (frame, vertex) pairs [m] (or [%]
/// after as_percent_of). worst_frame / worst_vertex locate `max` (vertex = mesh vertex id);
/// both are −1 when nothing was compared.
struct ErrorSummary {
  double max = 0; ///< max over (frame, vertex) of e
  double mean = 0; ///< mean over (frame, vertex) of e
  double rms = 0; ///< √(mean of e²)
  int worst_frame = -1; ///< frame of `max`
  int worst_vertex = -1; ///< vertex of `max`
  long samples = 0; ///< number of (frame, vertex) pairs compared
};

/// Errors between two trajectories of the same mesh. Frames are flat 3n vectors
/// (x0, y0, z0, x1, ...); frames 0..min(T_a, T_b)−1 are compared. `vertices` restricts the
/// comparison to those vertex ids (empty = all vertices).
/// Throws InputError if either trajectory is empty, a frame's size is not 3n with the n of
/// a.front(), or a vertex id is out of range [0, n).
ErrorSummary position_error(
    const std::vector<VecX>& a, const std::vector<VecX>& b, const std::vector<int>& vertices = {});

/// Errors of simulated frames (flat 3n) at the observed vertices against the observation:
/// frame t is compared with observation frame t, for t < min(T_frames, T_obs), at the entries
/// seen (Observation::valid; lost ones are skipped and not counted in `samples`).
/// Throws InputError if either is empty, frames differ in size, or an observed vertex id is
/// out of range of the frames.
ErrorSummary observation_error(const std::vector<VecX>& frames, const observe::Observation& obs);

/// The statistics of the union of the (frame, vertex) pairs of `parts` (e.g. one per motion):
/// the max with the worst frame and vertex of the part that holds it, mean and rms weighted by
/// each part's samples. One part is returned unchanged; no part gives the empty summary.
ErrorSummary combined_error(std::span<const ErrorSummary> parts);

/// The same errors as percentages of `length` [m] (paper 000 Table 1 uses the rest
/// bounding-box diagonal): max, mean and rms scaled by 100 / length. Throws InputError if
/// length is not positive and finite.
ErrorSummary as_percent_of(const ErrorSummary& error, double length);

} // namespace elastolearn::learn
