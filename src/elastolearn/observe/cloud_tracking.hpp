#pragma once
/// \file Physics-based tracking of a point-cloud sequence (paper 000 §5.3 and Fig. 3a, after
/// Schulman et al. 2013): the scene is simulated with its nominal material, backward Euler as the
/// scene says, and every step is pulled toward the cloud of the frame it solves for (CloudPull,
/// the Eq. 9 position term). The correspondences are re-found from the solved positions and the
/// step re-solved (EM: E = correspondences at the current mesh, M = the pulled step), a few times
/// per frame. The result is a trajectory of the whole mesh that follows the data where it is seen
/// and the physics elsewhere: the starting trajectory of learning from clouds.
///
/// Choices (docs/tracking.md explains them):
/// - σ is the scanner's accuracy (the caller passes the cloud file's noise_sigma), or half the
///   cloud's median point spacing when none is recorded; it is floored at a 48th of the longest
///   surface edge, where the surface samples (spaced 3σ) reach their cap of 16 per edge.
/// - Weights are the per-point normalised Gaussians of Eq. 9 (each cloud point pulls with total
///   weight 1), truncated at 1e-3 (3.72σ).
/// - Pull stiffness: the pull acts as a spring bed over the observed surface whose stiffness per
///   area is λ · M / h, M = λ_L + 2μ the nominal material's small-strain longitudinal modulus and
///   h the mean surface edge: λ = 1 makes the bed as stiff as a layer of the material one element
///   thick. Each point's stiffness is that times the observed area per point.
/// - Coarse to fine: when a frame's prediction is farther from its cloud than the 3.72σ reach
///   of the correspondences (a wrong nominal material, a fast motion), EM starts at σ·2^l with
///   coarser surface samples and halves σ every iteration down to σ.
/// - Frame 0 is the scene's initial state x₀ moved by the pull of cloud 0 against the elasticity:
///   the static solve of f(x) − f(x₀) + pull(x) = 0 (the forces that hold x₀ keep holding it, so
///   a body released from its rest shape does not sag first), its velocity kept; every later frame
///   is a dynamic step.
#include <elastolearn/capture/point_cloud.hpp>
#include <elastolearn/core/progress.hpp>
#include <elastolearn/sim/run_simulation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <string>
#include <vector>

namespace elastolearn::observe {

struct TrackingOptions {
  double sigma = 0; ///< σ [m], > 0 (default_tracking_sigma gives the default)
  double weight = 1; ///< λ, dimensionless pull stiffness (see the file comment), > 0
  /// τ ∈ [0, 1], the weight of a distance's tangential part in the pull (CloudPull): 1 pulls
  /// point to point (Eq. 9 as written), 0 point to plane.
  double tangential_weight = 1;
  double truncation = 1e-3; ///< correspondence truncation, in (0, 1)
  /// Most EM iterations per frame at the final σ (re-find pairs, re-solve the step), ≥ 1.
  int em_iterations = 5;
  /// The same for frame 0's static fit, which starts from the whole error of the initial
  /// condition and runs once (the cantilever benchmark's frame 0 settles in ~15), ≥ 1.
  int initial_em_iterations = 20;
  /// EM stops earlier when no vertex moved more than this times σ in the last re-solve, ≥ 0.
  double em_tolerance = 0.5;
  /// Throws InputError("tracking.<field>", ...).
  void validate() const;
};

/// The small-strain longitudinal modulus λ + 2μ [Pa] of a material (the diagonal of ∂P̂/∂σ at
/// rest): M of the pull's stiffness λ · M / h.
double longitudinal_modulus(const fem::MaterialModel& material);

/// σ for a sequence when the user gives none: the scanner's accuracy `recorded_noise` [m] if
/// positive (scan records it as noise_sigma), else half the median point spacing of the first
/// frame with at least two points. Throws InputError(source, ...) when neither exists.
double default_tracking_sigma(
    const capture::PointCloudSequence& clouds, double recorded_noise, const std::string& source);

/// One tracked frame.
struct TrackedFrame {
  double time = 0; ///< [s]
  Eigen::Index points = 0; ///< cloud points of the frame
  long pairs = 0; ///< correspondences of the last EM iteration
  int em_iterations = 0; ///< solves of this frame (0 for an empty cloud: the plain step)
  int newton_iterations = 0; ///< over its solves
  /// √(mean squared distance) from the frame's points to the tracked surface [m] (0 for an
  /// empty frame), and the same for the prediction the frame started from.
  double rms = 0;
  double rms_predicted = 0;
  /// The same over the points within k_inlier_distance·σ of the tracked surface, and how many
  /// points are farther (outliers of the scan, or parts the mesh does not reach): one outlier
  /// 0.3 m off among 20k points adds 2 mm to `rms`.
  double rms_inliers = 0;
  Eigen::Index outliers = 0;
};

/// Points farther than this many σ from the tracked surface count as outliers in TrackedFrame.
inline constexpr double k_inlier_distance = 10;

struct TrackingReport {
  bool completed = false; ///< every frame tracked
  std::string message; ///< why it stopped (names the frame), empty when completed
  std::vector<TrackedFrame> frames; ///< one per frame sent to the sink
  double sigma = 0; ///< σ used [m] (the requested one, or the floor)
  double stiffness_per_area = 0; ///< λ M / h [N/m³]
  int samples = 0; ///< surface samples at σ
  int levels = 0; ///< coarse-to-fine levels available
  double seconds = 0; ///< wall time
  /// Frames whose EM stopped early because a re-solve did not converge (they keep the last
  /// converged solve; frame 0 at worst the initial state), one line each.
  std::vector<std::string> notes;
};

/// Track `clouds` (frame t at clouds.start_time + t·dt) with `scene`: its dt must equal clouds.dt,
/// its initial state's time clouds.start_time and its frames + 1 states the clouds' frames
/// (mismatches throw InputError naming "<clouds_source>: dt" or ": /time"). Every tracked state
/// goes to `sink` (frame 0 first). A Newton failure stops the run (report.completed false, the
/// message names the frame); frames before it were sent. Throws InputError for bad options or
/// scene.
TrackingReport track_clouds(const sim::Scene& scene, const capture::PointCloudSequence& clouds,
    const std::string& clouds_source, const TrackingOptions& options, const sim::FrameSink& sink,
    const ProgressCallback& progress = {});

} // namespace elastolearn::observe
