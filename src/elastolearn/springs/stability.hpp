#pragma once
/// \file Largest stable stiffness of a scheme on a test system (paper 004 §1 and its stability
/// claim): bisection in log k of "the run stays bounded".
#include <elastolearn/springs/stiffness.hpp>

#include <functional>
#include <string>

namespace elastolearn::springs {

/// A system, its initial state and loads, for stability runs.
struct StabilityCase {
  std::string name;
  SpringSystem system;
  SpringState initial;
  Loads loads;
};

/// Single spring (2-node rope) released from 10 % stretch, no gravity.
StabilityCase single_spring_case(double stretch = 0.1);
/// Horizontal rope of `nodes` nodes pinned at node 0, falling under gravity g (−y).
StabilityCase rope_case(int nodes, double gravity = 9.81);
/// Hanging cloth n×n: horizontal at rest, two corners of one edge pinned, swinging down under
/// gravity (−y); 8-neighbour springs, unit spacing and masses.
StabilityCase hanging_cloth_case(int n, double gravity = 9.81);

/// Options of `find_stability_limit`.
struct StabilityOptions {
  double k_min = 10.0; ///< [N/m] lower end of the search
  double k_max = 1e7; ///< [N/m] upper end of the search
  int steps = 500; ///< steps per run
  double resolution = 1.05; ///< stop when k_unstable / k_stable < resolution
  /// Throws InputError("stability.<field>", ...).
  void validate() const;
};

/// Outcome: the bracket [largest_stable, smallest_unstable] of the stability limit.
struct StabilityResult {
  double largest_stable = 0.0; ///< 0 if even k_min is unstable
  double smallest_unstable = 0.0; ///< +inf if k_max is stable
  int runs = 0;
};

/// Run `steps` steps; stable if every position stays finite and within 100 × (size + 1) of its
/// initial value (size = rest bounding-box diagonal). Explicit blow-ups grow exponentially,
/// so the verdict is insensitive to that bound.
bool run_is_stable(SpringStepper& stepper, const StabilityCase& test, int steps);

/// Bisection in log k over [k_min, k_max] with `model(k)` building the scheme for stiffness k.
StabilityResult find_stability_limit(const std::function<StepperFactory(double k)>& model,
    const StabilityCase& test, const StabilityOptions& options = {});

} // namespace elastolearn::springs
