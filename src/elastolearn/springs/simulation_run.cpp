#include <elastolearn/springs/simulation_run.hpp>

#include <elastolearn/core/error.hpp>

namespace elastolearn::springs {

SimulationRecord run_simulation(SpringStepper& stepper, const SpringState& initial, int steps,
    int every, const ProgressCallback& progress, double divergence_factor) {
  if (steps < 0)
    throw InputError("simulation.steps", "must be >= 0, got " + std::to_string(steps));
  if (every < 1)
    throw InputError("simulation.every", "must be >= 1, got " + std::to_string(every));
  const Positions& rest = stepper.system().rest;
  const double size = (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
  const double bound = divergence_factor * (size + 1.0);
  SimulationRecord record;
  auto keep = [&](const SpringState& s, int step) {
    record.positions.push_back(s.x);
    record.velocities.push_back(s.v);
    record.time.push_back(step * stepper.dt());
  };
  SpringState state = initial;
  keep(state, 0);
  for (int step = 1; step <= steps; ++step) {
    stepper.step(state);
    if (!state.x.allFinite() || (state.x - rest).rowwise().norm().maxCoeff() > bound) {
      record.diverged = true;
      record.message = "simulation diverged at step " + std::to_string(step)
          + " (t = " + std::to_string(step * stepper.dt()) + " s); frames before it are kept";
      break;
    }
    record.steps_done = step;
    if (step % every == 0 || step == steps)
      keep(state, step);
    if (progress && (step % 50 == 0 || step == steps))
      progress(step, steps, "simulating");
  }
  if (!record.diverged)
    record.message = "completed";
  return record;
}

} // namespace elastolearn::springs
