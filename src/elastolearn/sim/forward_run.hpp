#pragma once
/// \file A forward simulation kept whole: every state of a scene's run in memory, for callers that
/// compare or learn from trajectories (the learning loop, fits, evaluation, tests, benchmarks),
/// and the scene with a correction attached, the run they most often make. Streaming to a file
/// is run_simulation's job.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/sim/scene.hpp>

#include <memory>
#include <string>
#include <vector>

namespace elastolearn::sim {

/// The scene with `correction` attached to its material (null: none); everything else is kept.
Scene with_correction(const Scene& scene, std::shared_ptr<const material::Correction> correction);

/// Every state of a forward simulation.
struct ForwardRun {
  /// Frames 0..scene.frames, each flat 3n [m]; empty if the run stopped early.
  std::vector<VecX> positions;
  VecX initial_velocity; ///< of frame 0, flat 3n [m/s] (empty if the initial condition failed)
  bool completed = false; ///< every frame simulated
  std::string message; ///< why the run stopped early (names the frame); empty when completed
  /// The first frame whose step converged only in substeps (Simulator::step); 0: none did.
  int first_substepped_frame = 0;
};

/// Simulate `scene` (run_simulation) and keep every state. A divergence is a result (completed
/// false, message), not an exception. Throws InputError for an invalid scene (Scene::validate).
ForwardRun simulate_positions(const Scene& scene, const ProgressCallback& progress = {});

} // namespace elastolearn::sim
