#include <elastolearn/springs/reference_simulator.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/spring_kernels.hpp>

#include <cmath>

namespace elastolearn::springs {

ReferenceSimulator::ReferenceSimulator(
    SpringSystem system, SpringLaw law, double dt, const Loads& loads)
    : m_system(std::move(system))
    , m_law(law)
    , m_dt(dt) {
  m_law.validate();
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("simulation.dt", "must be > 0, got " + std::to_string(dt));
  m_spring_forces.resize(m_system.spring_count(), 3);
  m_node_forces.resize(m_system.node_count(), 3);
  set_loads(loads);
}

void ReferenceSimulator::set_loads(const Loads& loads) {
  m_external = detail::checked_forces(m_system, loads);
  m_gravity = loads.gravity;
}

void ReferenceSimulator::step(SpringState& state) {
  const SpringLaw& law = m_law;
  detail::spring_forces(
      m_system, state.x, state.v, [&law](double e, double rate) { return law.force(e, rate); },
      m_spring_forces);
  detail::gather(m_system, m_spring_forces, m_node_forces);
  detail::semi_implicit_update(m_system, m_node_forces, m_external, m_gravity, m_dt, state);
}

} // namespace elastolearn::springs
