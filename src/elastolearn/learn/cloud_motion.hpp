#pragma once
/// \file Learning from point clouds (paper 000 §5.3): a motion captured as clouds gets the
/// observations the learning stages use by physics-based tracking (observe/cloud_tracking.hpp:
/// the scene simulated while pulled toward each frame's cloud by Eq. (9)'s position term,
/// Fig. 3a): the tracked surface vertices, in the frames where the clouds see them
/// (observe/cloud_observation.hpp), are the data every later stage follows — noise estimate,
/// parameter fit, space-time optimisation, constrained simulation, validation. The tracking uses
/// the material it is given (the recipe tracks with the nominal and re-tracks with the fitted
/// nominal), because where a cloud does not see the surface the tracked mesh follows that material.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/observe/cloud_tracking.hpp>

#include <string>

namespace elastolearn::learn {

/// What observing a cloud motion did.
struct CloudMotionReport {
  observe::TrackingReport tracking;
  double sigma = 0; ///< σ of the correspondences [m] (tracking's)
  long seen = 0; ///< (frame, vertex) entries seen
  long entries = 0; ///< frames × surface vertices
  /// "tracked 201 frames in 3.2 s (σ 1 mm, surface rms 0.4 mm); 61 % of the surface
  /// vertex-frames seen".
  std::string describe() const;
};

/// Set `motion.observed` from `motion.captured` (which must be set): track the clouds with the
/// motion's scene and `material`, the pull as stiff as the scene's own nominal makes it (λ = 1
/// for that material), then observe the surface vertices of the tracked trajectory
/// where the clouds see them. Throws InputError naming the motion when the tracking fails (a Newton
/// failure: the frame) or sees nothing.
CloudMotionReport observe_cloud_motion(
    Motion& motion, const fem::MaterialModel& material, const ProgressCallback& progress = {});

} // namespace elastolearn::learn
