#pragma once
/// \file A forward simulation of a mass-spring system with recording, progress and divergence
/// detection (a diverging run stops with a message naming the frame and keeps earlier frames).
#include <elastolearn/core/progress.hpp>
#include <elastolearn/springs/spring_system.hpp>

#include <string>
#include <vector>

namespace elastolearn::springs {

/// Recorded frames of a run (frame 0 is the initial state).
struct SimulationRecord {
  std::vector<Positions> positions; ///< per recorded frame, n×3 [m]
  std::vector<Positions> velocities; ///< per recorded frame, n×3 [m/s]
  std::vector<double> time; ///< [s]
  bool diverged = false;
  int steps_done = 0;
  std::string message; ///< "completed" or why it stopped
};

/// Run `steps` steps from `initial`, recording every `every`-th state (and the last one).
/// Divergence: a non-finite position, or a node farther than `divergence_factor` × (rest size
/// + 1) from its rest position. Throws InputError for steps < 0 or every < 1.
SimulationRecord run_simulation(SpringStepper& stepper, const SpringState& initial, int steps,
    int every = 1, const ProgressCallback& progress = {}, double divergence_factor = 1000.0);

} // namespace elastolearn::springs
