#pragma once
/// \file How a trajectory's vertex position errors are distributed over frames and sizes: the
/// error per frame (a learning report's "error per frame" plot) and histograms of the errors of
/// every (frame, vertex) pair (paper 000 Fig. 18). Complements trajectory_error.hpp, which
/// summarises them into one ErrorSummary.
#include <elastolearn/core/types.hpp>
#include <elastolearn/observe/observation.hpp>

#include <span>
#include <vector>

namespace elastolearn::learn {

/// e(t, j) = ‖a_t(v_j) − b_t(v_j)‖ [m]: one row per frame t < min(T_a, T_b), one column per
/// compared vertex v_j (`vertices`, or every vertex when empty). Frames are flat 3n vectors.
/// Throws InputError if a trajectory is empty, a frame is not 3n long (n of a.front()) or a vertex
/// id is out of range.
Eigen::MatrixXd vertex_errors(
    const std::vector<VecX>& a, const std::vector<VecX>& b, const std::vector<int>& vertices = {});

/// e(t, j) = ‖x_t(v_j) − o_t(j)‖ [m] of simulated frames against observation `obs` (v_j its
/// vertex ids), frames t < min(T_frames, T_obs). Throws InputError as observation_error does.
Eigen::MatrixXd vertex_errors(const std::vector<VecX>& frames, const observe::Observation& obs);

/// Per frame (row of `errors`): the largest and the root-mean-square error over its columns.
struct FrameErrors {
  std::vector<double> max; ///< [m]
  std::vector<double> rms; ///< [m]
};
FrameErrors frame_errors(const Eigen::MatrixXd& errors);

/// `bins` + 1 edges spaced evenly in log between `low` and `high` (0 < low < high, bins ≥ 1;
/// else InputError("error histogram", ...)).
std::vector<double> log_bin_edges(double low, double high, int bins);

/// How many values fall in [edges[i], edges[i+1]) for each of the edges.size() − 1 bins; values
/// below the first edge count in the first bin and values at or above the last in the last, so
/// that the counts add up to values.size() (an error histogram must show every error).
/// `edges` must increase (else InputError("error histogram", ...)).
std::vector<long> histogram_counts(std::span<const double> values, std::span<const double> edges);

} // namespace elastolearn::learn
