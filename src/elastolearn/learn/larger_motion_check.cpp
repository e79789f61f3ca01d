#include <elastolearn/learn/larger_motion_check.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/forward_run.hpp>

namespace elastolearn::learn {

LargerMotionCheck check_larger_motion(const sim::Scene& scene, const std::string& name) {
  LargerMotionCheck out;
  out.checked = true;
  const sim::ForwardRun run = sim::simulate_positions(sim::amplified_scene(scene, kLargerMotion));
  out.completed = run.completed;
  out.first_substepped_frame = run.first_substepped_frame;
  if (!run.completed)
    out.message = name + ": " + run.message;
  return out;
}

} // namespace elastolearn::learn
