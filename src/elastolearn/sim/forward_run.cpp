#include <elastolearn/sim/forward_run.hpp>
#include <elastolearn/sim/run_simulation.hpp>

namespace elastolearn::sim {

Scene with_correction(const Scene& scene, std::shared_ptr<const material::Correction> correction) {
  Scene out = scene;
  out.material.correction = std::move(correction);
  return out;
}

ForwardRun simulate_positions(const Scene& scene, const ProgressCallback& progress) {
  ForwardRun run;
  run.positions.reserve(static_cast<size_t>(scene.frames) + 1);
  const auto report = run_simulation(
      scene,
      [&](int frame, double, const VecX& x, const VecX& v) {
        if (frame == 0)
          run.initial_velocity = v;
        run.positions.push_back(x);
      },
      progress);
  run.completed = report.completed;
  run.message = report.message;
  run.first_substepped_frame = report.first_substepped_frame;
  if (!run.completed)
    run.positions.clear();
  return run;
}

} // namespace elastolearn::sim
