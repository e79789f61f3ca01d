#include <elastolearn/core/interrupt.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <cstdio>

namespace elastolearn::sim {

SimulationReport run_simulation(
    const Scene& scene, const FrameSink& sink, const ProgressCallback& progress) {
  Simulator simulator(scene);
  const NewtonReport initial = simulator.apply_initial_condition();
  if (!initial.converged) {
    SimulationReport report;
    report.initial = initial;
    report.message = "initial condition failed: " + initial.message;
    return report;
  }
  SimulationReport report = run_simulation(simulator, scene.frames, sink, progress);
  report.initial = initial;
  return report;
}

SimulationReport run_simulation(
    Simulator& simulator, int frames, const FrameSink& sink, const ProgressCallback& progress) {
  SimulationReport report;
  const auto start = Clock::now();
  if (sink)
    sink(0, simulator.time(), simulator.positions(), simulator.velocities());
  report.frames_written = 1;
  for (int frame = 1; frame <= frames; ++frame) {
    if (interrupt_requested()) {
      report.message = "interrupted before frame " + std::to_string(frame) + "; kept frames 0.."
          + std::to_string(frame - 1);
      break;
    }
    const NewtonReport step = simulator.step();
    report.newton_iterations += step.iterations;
    report.linear_iterations += step.linear_iterations;
    report.timings += step.timings;
    if (!step.converged) {
      report.message = "diverged at frame " + std::to_string(frame)
          + " (t = " + std::to_string(simulator.time() + simulator.scene().dt)
          + " s): " + step.message + "; kept frames 0.." + std::to_string(frame - 1);
      break;
    }
    if (step.substeps > 1 && report.substepped_frames++ == 0)
      report.first_substepped_frame = frame;
    if (sink)
      sink(frame, simulator.time(), simulator.positions(), simulator.velocities());
    ++report.frames_written;
    if (progress) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "newton %d it, residual %.2e", step.iterations, step.residual);
      progress(frame, frames, buf);
    }
  }
  report.completed = report.frames_written == frames + 1;
  report.seconds = seconds_since(start);
  return report;
}

} // namespace elastolearn::sim
