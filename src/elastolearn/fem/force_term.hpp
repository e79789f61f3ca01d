#pragma once
/// \file One small interface for every force term (as PolyFEM's forms): elastic(+correction),
/// damping, gravity, loads, and later position pulls. The integrator sums terms and never knows
/// which material it runs.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/system_matrix.hpp>

namespace elastolearn::fem {

/// The state a force is evaluated at: flat 3n positions and velocities, and time [s].
struct ForceState {
  const VecX& x;
  const VecX& v;
  double time = 0;
};

class ForceTerm {
  public:
  virtual ~ForceTerm() = default;
  /// f += force(x, v, t) (full 3n vector, N).
  virtual void add_force(const ForceState& state, VecX& f) = 0;
  /// A += c_x·K + c_v·D over the free dofs, where K ≈ −∂f/∂x and D ≈ −∂f/∂v are the term's
  /// positive semi-definite (projected) Jacobians at `state`. Terms may reuse work cached by the
  /// last add_force at the same state (Newton always asks for the residual first). Terms without
  /// Jacobians (constant loads) add nothing.
  virtual void add_jacobian(const ForceState& state, double c_x, double c_v, SystemMatrix& A) { }
  /// Both, in that order.
  void add_force_and_jacobian(
      const ForceState& state, double c_x, double c_v, VecX& f, SystemMatrix& A) {
    add_force(state, f);
    add_jacobian(state, c_x, c_v, A);
  }
};

} // namespace elastolearn::fem
