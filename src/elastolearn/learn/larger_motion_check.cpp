#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/larger_motion_check.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/forward_run.hpp>
#include <elastolearn/sim/simulator.hpp>

namespace elastolearn::learn {
namespace {

/// The largest vertex displacement from `rest` in `x` [m] and, if `direction` is non-null, its
/// unit direction.
double largest_displacement(const VecX& x, const VecX& rest, Vec3* direction = nullptr) {
  double largest = 0;
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) {
    const Vec3 d = x.segment<3>(3 * v) - rest.segment<3>(3 * v);
    if (d.norm() > largest) {
      largest = d.norm();
      if (direction)
        *direction = d / largest;
    }
  }
  return largest;
}

/// The static equilibrium of the scene's object under the body acceleration `a` alone, in one
/// increment from `start` if it is given and that converges, else in the scene's load steps from
/// rest; where it is found, *equilibrium (if non-null) = its positions.
sim::NewtonReport hold_droop(
    sim::Scene scene, const Vec3& a, const VecX& start = {}, VecX* equilibrium = nullptr) {
  scene.initial = {};
  scene.initial.kind = sim::InitialCondition::Kind::StaticLoad;
  scene.gravity = a;
  if (start.size() > 0) {
    sim::Simulator simulator(scene);
    simulator.set_state(start, VecX::Zero(start.size()), 0.0);
    const sim::NewtonReport held = simulator.solve_static(1);
    if (held.converged) {
      if (equilibrium)
        *equilibrium = simulator.positions();
      return held;
    }
  }
  sim::Simulator simulator(scene);
  const sim::NewtonReport held = simulator.apply_initial_condition();
  if (held.converged && equilibrium)
    *equilibrium = simulator.positions();
  return held;
}

} // namespace

Droop reference_droop(const sim::Scene& scene, const std::vector<VecX>& run) {
  const VecX rest = flatten(scene.mesh.rest_positions());
  double moved = 0;
  Vec3 direction = Vec3::Zero();
  for (const VecX& x : run) {
    Vec3 d;
    const double u = largest_displacement(x, rest, &d);
    if (u > moved) {
      moved = u;
      direction = d;
    }
  }
  if (!(moved > 0))
    return {};
  // The linear response to a small trial load (0.1 m/s², a hundredth of a weight), scaled.
  const Vec3 trial = 0.1 * direction;
  VecX held;
  if (!hold_droop(scene, trial, {}, &held).converged)
    return {};
  const double trial_droop = largest_displacement(held, rest);
  if (!(trial_droop > 0))
    return {};
  Vec3 a = trial * (kLargerMotion * moved / trial_droop);
  for (int halvings = 0; halvings < 4; ++halvings, a *= 0.5)
    if (hold_droop(scene, a, {}, &held).converged)
      return { a, held };
  return {};
}

LargerMotionCheck check_larger_motion(
    const sim::Scene& scene, const std::string& name, const Vec3& droop, const VecX& start) {
  LargerMotionCheck out;
  out.checked = true;
  const sim::ForwardRun run = sim::simulate_positions(sim::amplified_scene(scene, kLargerMotion));
  out.completed = run.completed;
  out.first_substepped_frame = run.first_substepped_frame;
  if (!run.completed) {
    out.message = name + " driven " + to_text(kLargerMotion) + "× as hard (" + run.message + ")";
    return out;
  }
  if (droop.isZero(0))
    return out;
  const sim::NewtonReport held = hold_droop(scene, droop, start);
  if (!held.converged) {
    out.completed = false;
    out.message = "the droop of " + name + " under a body load of " + to_text(droop.norm())
        + " m/s² (" + held.message + ")";
  }
  return out;
}

} // namespace elastolearn::learn
