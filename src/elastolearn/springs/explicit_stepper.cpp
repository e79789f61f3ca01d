#include <elastolearn/springs/explicit_stepper.hpp>

#include <elastolearn/core/error.hpp>

#include <cmath>
#include <string>

namespace elastolearn::springs {

ExplicitStepper::ExplicitStepper(SpringSystem system, double dt, const Loads& loads)
    : m_system(std::move(system))
    , m_dt(dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("simulation.dt", "must be > 0, got " + std::to_string(dt));
  m_spring_forces.resize(m_system.spring_count(), 3);
  m_node_forces.resize(m_system.node_count(), 3);
  set_loads(loads);
}

void ExplicitStepper::set_loads(const Loads& loads) {
  m_external = detail::checked_forces(m_system, loads);
  m_gravity = loads.gravity;
}

void ExplicitStepper::loads_only_step(SpringState& state) {
  m_node_forces.setZero();
  detail::semi_implicit_update(m_system, m_node_forces, m_external, m_gravity, m_dt, state);
}

} // namespace elastolearn::springs
