#include <elastolearn/springs/stability.hpp>

#include <elastolearn/core/error.hpp>

#include <cmath>
#include <limits>

namespace elastolearn::springs {

StabilityCase single_spring_case(double stretch) {
  StabilityCase c { "single spring", make_rope(2), {}, {} };
  c.initial = rest_state(c.system);
  c.initial.x(1, 0) += stretch;
  return c;
}

StabilityCase rope_case(int nodes, double gravity) {
  StabilityCase c { "rope " + std::to_string(nodes), make_rope(nodes), {}, {} };
  c.initial = rest_state(c.system);
  c.loads.gravity = Vec3(0.0, -gravity, 0.0);
  return c;
}

StabilityCase hanging_cloth_case(int n, double gravity) {
  ClothOptions o;
  o.columns = o.rows = n;
  o.plane = ClothPlane::horizontal;
  o.pins = ClothPins::top_corners;
  StabilityCase c { "cloth " + std::to_string(n) + "x" + std::to_string(n), make_cloth(o), {}, {} };
  c.initial = rest_state(c.system);
  c.loads.gravity = Vec3(0.0, -gravity, 0.0);
  return c;
}

void StabilityOptions::validate() const {
  if (!(k_min > 0.0) || !(k_max > k_min))
    throw InputError("stability.k_min", "need 0 < k_min < k_max");
  if (steps < 1)
    throw InputError("stability.steps", "must be >= 1");
  if (!(resolution > 1.0))
    throw InputError("stability.resolution", "must be > 1");
}

bool run_is_stable(SpringStepper& stepper, const StabilityCase& test, int steps) {
  const Positions& rest = test.system.rest;
  const double size = (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
  const double bound = 100.0 * (size + 1.0);
  stepper.set_loads(test.loads);
  SpringState state = test.initial;
  for (int s = 0; s < steps; ++s) {
    stepper.step(state);
    if (!state.x.allFinite())
      return false;
    if ((state.x - test.initial.x).rowwise().norm().maxCoeff() > bound)
      return false;
  }
  return true;
}

StabilityResult find_stability_limit(const std::function<StepperFactory(double k)>& model,
    const StabilityCase& test, const StabilityOptions& options) {
  options.validate();
  StabilityResult result;
  auto stable = [&](double k) {
    ++result.runs;
    std::unique_ptr<SpringStepper> stepper = model(k)(test.system);
    return run_is_stable(*stepper, test, options.steps);
  };
  if (stable(options.k_max)) {
    result.largest_stable = options.k_max;
    result.smallest_unstable = std::numeric_limits<double>::infinity();
    return result;
  }
  if (!stable(options.k_min)) {
    result.smallest_unstable = options.k_min;
    return result;
  }
  double lo = options.k_min, hi = options.k_max;
  while (hi / lo > options.resolution) {
    const double mid = std::sqrt(lo * hi);
    (stable(mid) ? lo : hi) = mid;
  }
  result.largest_stable = lo;
  result.smallest_unstable = hi;
  return result;
}

} // namespace elastolearn::springs
