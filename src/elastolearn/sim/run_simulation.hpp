#pragma once
/// \file Run a scene frame by frame, streaming frames to a sink (e.g. an HDF5 writer).
#include <elastolearn/core/progress.hpp>
#include <elastolearn/sim/scene.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <functional>
#include <string>

namespace elastolearn::sim {

/// Receives every recorded state: frame index (0 = initial state), time [s], x and v (flat 3n).
using FrameSink = std::function<void(int frame, double time, const VecX& x, const VecX& v)>;

struct SimulationReport {
  bool completed = false; ///< all frames simulated
  int frames_written = 0; ///< states passed to the sink (initial state included)
  std::string message; ///< why it stopped early (names the frame), empty when completed
  double seconds = 0; ///< wall time of the stepping
  long newton_iterations = 0; ///< over all steps
  long linear_iterations = 0;
  SolverTimings timings;
  NewtonReport initial; ///< the initial-condition solve (static load), if any
  /// Steps that converged only in substeps (NewtonReport::substeps > 1), and the first of them
  /// (0: none).
  int substepped_frames = 0;
  int first_substepped_frame = 0;
};

/// Simulate scene.frames steps from the scene's initial condition. Divergence (Newton failure,
/// NaN) stops the run with a message naming the frame; frames before it were already sent.
SimulationReport run_simulation(
    const Scene& scene, const FrameSink& sink, const ProgressCallback& progress = {});

/// Same, on an existing simulator whose state is already initialised (for callers that add
/// force terms, e.g. control forces).
SimulationReport run_simulation(
    Simulator& simulator, int frames, const FrameSink& sink, const ProgressCallback& progress = {});

} // namespace elastolearn::sim
