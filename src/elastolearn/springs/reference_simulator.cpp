#include <elastolearn/springs/reference_simulator.hpp>

namespace elastolearn::springs {

ReferenceSimulator::ReferenceSimulator(
    SpringSystem system, SpringLaw law, double dt, const Loads& loads)
    : ExplicitStepper(std::move(system), dt, loads)
    , m_law(law) {
  m_law.validate();
}

void ReferenceSimulator::step(SpringState& state) {
  const SpringLaw& law = m_law;
  semi_implicit_step(state, [&law](double e, double rate) { return law.force(e, rate); });
}

} // namespace elastolearn::springs
