#pragma once
/// \file One recorded motion of the object being learned: the scene that produced it (the nominal
/// material, no correction) and its observations, or the point clouds they are derived from.
/// Learning takes one or more (a training set, io/training_set.hpp).
#include <elastolearn/capture/point_cloud.hpp>
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <memory>
#include <string>

namespace elastolearn::learn {

/// A motion captured as point clouds (paper 000 §5.3): what learning derives its observations
/// from (learn/cloud_motion.hpp).
struct CloudCapture {
  capture::PointCloudSequence clouds; ///< scene.frames + 1 frames of scene.dt
  /// The scanner's accuracy σ [m] (the file's noise_sigma), or 0 when unknown: tracking then
  /// takes half the clouds' point spacing (observe::default_tracking_sigma).
  double sigma = 0;
  std::string source; ///< the cloud file, for messages
};

struct Motion {
  std::string name; ///< for messages and the learned file (e.g. the observation file's path)
  sim::Scene scene; ///< nominal material, no correction
  /// scene.frames + 1 frames of scene.dt. For a cloud capture, empty until learn_material derives
  /// it (observe_cloud_motion).
  observe::Observation observed;
  /// Set when the motion was captured as point clouds (shared: a motion is copied per stage).
  std::shared_ptr<const CloudCapture> captured = nullptr;
  /// `observed` smoothed in time to the noise level (observe::smooth_to_noise), or null. The
  /// stages that differentiate positions twice (the space-time solve, the constrained forward
  /// simulation) follow these; every comparison of a simulation with the data (the forward error,
  /// the forward fit) uses `observed` itself, whose noise has zero mean, where the smoothing's
  /// bias would be taken for signal. Shared: a motion is copied per stage.
  std::shared_ptr<const observe::Observation> smoothed = nullptr;

  /// The positions the differentiating stages follow: `smoothed` if set, else `observed`.
  const observe::Observation& followed() const { return smoothed ? *smoothed : observed; }
};

} // namespace elastolearn::learn
