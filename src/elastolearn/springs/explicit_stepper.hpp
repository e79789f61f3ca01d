#pragma once
/// \file The base of the explicit mass-spring steppers (reference, paper, corrected explicit): the
/// system, time step and loads they hold alike, and the one semi-implicit Euler step they share.
/// A stepper supplies only what is its own: the force along each spring (reference: a
/// `SpringLaw`; corrected explicit: a `LearnedSpring`'s impulse) or, for the paper's scheme, the
/// increments it applies after a loads-only step.
#include <elastolearn/springs/spring_kernels.hpp>
#include <elastolearn/springs/spring_system.hpp>

namespace elastolearn::springs {

/// An explicit stepper: each node's update depends only on the nodes it shares a spring with.
class ExplicitStepper : public SpringStepper {
  public:
  void set_loads(const Loads& loads) final;
  const SpringSystem& system() const final { return m_system; }
  double dt() const final { return m_dt; }
  bool is_local() const final { return true; }

  protected:
  /// Throws InputError("simulation.dt") for dt ≤ 0 or not finite, and for malformed loads.
  ExplicitStepper(SpringSystem system, double dt, const Loads& loads);

  /// One semi-implicit Euler step of the free nodes, v += dt ((F + F_ext)/m + g), x += dt v
  /// (pinned nodes keep v = 0). F sums force(e, ė) u over a node's springs (+ at a spring's first
  /// node, − at its second), with elongation e, its rate ė and direction u of each spring at the
  /// start of the step.
  template <class ForceFn> void semi_implicit_step(SpringState& state, ForceFn&& force) {
    detail::spring_forces(m_system, state.x, state.v, force, m_spring_forces);
    detail::gather(m_system, m_spring_forces, m_node_forces);
    detail::semi_implicit_update(m_system, m_node_forces, m_external, m_gravity, m_dt, state);
  }
  /// The same step without spring forces: external loads and gravity only.
  void loads_only_step(SpringState& state);

  private:
  SpringSystem m_system;
  double m_dt;
  Positions m_external; ///< n×3 external forces [N]
  Vec3 m_gravity = Vec3::Zero();
  Positions m_spring_forces; ///< s×3 scratch
  Positions m_node_forces; ///< n×3 scratch
};

} // namespace elastolearn::springs
