#pragma once
/// \file Static equilibrium of a time-stepping scheme as the fixed point of its step map:
/// Φ(x, v) = (x, v). For the reference and corrected schemes this is v = 0 and Σ forces = 0; for
/// the paper's scheme the fixed point has v ≠ 0 (its double position integration), which is why
/// the equilibrium must be taken from the step map itself and not from a force balance.
#include <elastolearn/springs/spring_system.hpp>

#include <array>
#include <string>

namespace elastolearn::springs {

/// Options of `solve_fixed_point`.
struct FixedPointOptions {
  int max_iterations = 40;
  /// Converged when max |Δx| ≤ tolerance·ℓ and max |Δv| ≤ tolerance·ℓ/dt over one step, with
  /// ℓ = 1 + max |x| (so the test is relative to the system's size).
  double tolerance = 1e-12;
  /// Finite-difference step relative to ℓ (positions) and ℓ/dt (velocities).
  double fd_step = 1e-7;
  /// Components (x, y, z) that are unknowns. A component that is constant in the state and
  /// receives no load stays constant by symmetry and can be frozen (e.g. z of a planar cloth).
  std::array<bool, 3> components = { true, true, true };
  /// Throws InputError("fixed point.<field>", ...).
  void validate() const;
};

/// Outcome of `solve_fixed_point` (a result with a reason, not an exception).
struct FixedPointResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0; ///< final max-norm residual, relative as in FixedPointOptions::tolerance
  std::string message;
};

/// Newton's method on G(s) = Φ(s) − s over the free nodes' active (x, v) components, starting
/// from `state` and overwriting it with the fixed point. The Jacobian is taken by forward finite
/// differences of the step map: column groups of a distance-2 colouring of the spring graph when
/// the stepper is local (a few dozen steps per Jacobian at any size), one column at a time
/// otherwise. Linear systems are solved with Eigen::SparseLU. Backtracking on ‖G‖∞.
FixedPointResult solve_fixed_point(
    SpringStepper& stepper, SpringState& state, const FixedPointOptions& options = {});

} // namespace elastolearn::springs
