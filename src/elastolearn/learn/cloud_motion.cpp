#include <elastolearn/learn/cloud_motion.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/cloud_observation.hpp>

#include <cmath>
#include <cstdio>

namespace elastolearn::learn {

std::string CloudMotionReport::describe() const {
  double squares = 0;
  for (const auto& f : tracking.frames)
    squares += f.rms_inliers * f.rms_inliers;
  const double rms = tracking.frames.empty()
      ? 0
      : std::sqrt(squares / static_cast<double>(tracking.frames.size()));
  char text[256];
  std::snprintf(text, sizeof text,
      "tracked %zu frames in %.1f s (σ %.3g m, cloud-to-surface rms %.3g m); %.1f %% of the "
      "surface vertex-frames seen",
      tracking.frames.size(), tracking.seconds, sigma, rms,
      entries > 0 ? 100.0 * static_cast<double>(seen) / static_cast<double>(entries) : 0.0);
  return text;
}

CloudMotionReport observe_cloud_motion(
    Motion& motion, const fem::MaterialModel& material, const ProgressCallback& progress) {
  if (!motion.captured)
    throw InputError(motion.name, "is not a point-cloud capture");
  const CloudCapture& capture = *motion.captured;
  sim::Scene scene = motion.scene;
  scene.material = material;
  observe::TrackingOptions options;
  options.sigma = observe::default_tracking_sigma(capture.clouds, capture.sigma, capture.source);
  // The pull as stiff as with the motion's own (given) nominal, whatever material tracks: its
  // stiffness must not follow a fitted material, or a fit that went soft would track with no
  // pull and find its own motion in the data.
  options.weight = observe::longitudinal_modulus(motion.scene.material)
      / observe::longitudinal_modulus(material);
  // Point to plane at the finest σ: the tangential part of a point-to-point pull is noise and
  // sampling that drags the surface sideways (measured on a scanned bar: tracked surface 0.57 mm
  // tangential / 0.22 mm normal RMS from the truth point to point, 0.065 / 0.030 mm point to
  // plane), and the fits take the tracked positions as data. The scene's physics from its known
  // initial state carries the motion along the surface.
  options.tangential_weight = 0;
  std::vector<Positions> tracked;
  tracked.reserve(static_cast<size_t>(scene.frames) + 1);
  CloudMotionReport report;
  report.tracking = observe::track_clouds(
      scene, capture.clouds, capture.source, options,
      [&](int, double, const VecX& x, const VecX&) { tracked.emplace_back(unflatten(x)); },
      progress);
  if (!report.tracking.completed)
    throw InputError(capture.source, "tracking failed: " + report.tracking.message);
  report.sigma = report.tracking.sigma;
  observe::CloudObservationOptions observing;
  observing.sigma = report.sigma;
  motion.observed = observe::observe_clouds(
      motion.scene.mesh.surface_vertices(), tracked, capture.clouds, observing);
  report.seen = motion.observed.num_valid();
  report.entries = static_cast<long>(motion.observed.num_frames())
      * static_cast<long>(motion.observed.num_observed());
  return report;
}

} // namespace elastolearn::learn
