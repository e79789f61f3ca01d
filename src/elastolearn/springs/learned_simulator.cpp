#include <elastolearn/springs/learned_simulator.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/implicit_simulator.hpp>
#include <elastolearn/springs/spring_kernels.hpp>

#include <cmath>

namespace elastolearn::springs {

std::string_view to_string(LearnedMode mode) {
  switch (mode) {
  case LearnedMode::paper:
    return "paper";
  case LearnedMode::corrected_explicit:
    return "explicit";
  case LearnedMode::corrected_implicit:
    return "implicit";
  }
  return "unknown";
}

LearnedMode learned_mode_from_string(const std::string& name, const std::string& where) {
  for (LearnedMode m :
      { LearnedMode::paper, LearnedMode::corrected_explicit, LearnedMode::corrected_implicit })
    if (to_string(m) == name)
      return m;
  throw InputError(
      where, "unknown mode '" + name + "' (expected one of: paper, explicit, implicit)");
}

std::string_view to_string(LinearSolverKind kind) {
  switch (kind) {
  case LinearSolverKind::automatic:
    return "auto";
  case LinearSolverKind::direct:
    return "direct";
  case LinearSolverKind::cg:
    return "cg";
  }
  return "unknown";
}

LinearSolverKind linear_solver_from_string(const std::string& name, const std::string& where) {
  for (LinearSolverKind k :
      { LinearSolverKind::automatic, LinearSolverKind::direct, LinearSolverKind::cg })
    if (to_string(k) == name)
      return k;
  throw InputError(where, "unknown solver '" + name + "' (expected one of: auto, direct, cg)");
}

void LearnedSimulatorOptions::validate() const {
  if (!(dt >= 0.0) || !std::isfinite(dt))
    throw InputError(
        "simulation.dt", "must be > 0 (or 0 for the spring's dt), got " + std::to_string(dt));
  if (!(cg_tolerance > 0.0) || cg_tolerance >= 1.0)
    throw InputError(
        "simulation.cg_tolerance", "must be in (0, 1), got " + std::to_string(cg_tolerance));
  if (cg_max_iterations < 1)
    throw InputError("simulation.cg_max_iterations", "must be >= 1");
  if (direct_max_dofs < 0)
    throw InputError("simulation.direct_max_dofs", "must be >= 0");
}

// --- paper mode --------------------------------------------------------------------------

PaperSimulator::PaperSimulator(
    SpringSystem system, LearnedSpring spring, double dt, const Loads& loads)
    : ExplicitStepper(std::move(system), dt, loads)
    , m_spring(std::move(spring)) {
  if (std::abs(dt - m_spring.dt()) > 1e-12 * m_spring.dt())
    throw InputError("simulation.dt",
        "paper mode predicts exactly one training step: dt must equal "
        "the spring's training dt "
            + std::to_string(m_spring.dt()) + ", got " + std::to_string(dt));
  // this->system(): the parameter `system` (moved into the base) hides the accessor.
  const int n = this->system().node_count(), s = this->system().spring_count();
  m_spring_dx.resize(s, 3);
  m_spring_dv.resize(s, 3);
  m_node_dx.resize(n, 3);
  m_node_dv.resize(n, 3);
}

void PaperSimulator::step(SpringState& state) {
  const SpringSystem& sys = system();
  // 1. External forces only: one semi-implicit Euler step (paper §2, "First, we apply external
  //    (gravity) forces").
  loads_only_step(state);
  // 2. Each spring predicts (Δe, Δv) in its 1-D frame from the updated state; the prediction is
  //    oriented along the spring, with opposite signs at its two nodes (paper Fig. 1).
  detail::parallel_blocks(sys.spring_count(), [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      const detail::SpringFrame fr = detail::spring_frame(sys, state.x, state.v, s);
      const Vec2 delta = m_spring.predict(fr.e, fr.rate);
      m_spring_dx.row(s) = delta[0] * fr.u.transpose();
      m_spring_dv.row(s) = delta[1] * fr.u.transpose();
    }
  });
  // 3. Average the contributions of a node's springs (paper §6) and apply them.
  detail::gather(sys, m_spring_dx, m_node_dx, true);
  detail::gather(sys, m_spring_dv, m_node_dv, true);
  detail::parallel_blocks(sys.node_count(), [&](int begin, int end) {
    for (int a = begin; a < end; ++a) {
      if (sys.pinned[a])
        continue;
      state.x.row(a) += m_node_dx.row(a);
      state.v.row(a) += m_node_dv.row(a);
    }
  });
}

// --- corrected explicit mode ---------------------------------------------------------------

ExplicitLearnedSimulator::ExplicitLearnedSimulator(
    SpringSystem system, LearnedSpring spring, double dt, const Loads& loads)
    : ExplicitStepper(std::move(system), dt, loads)
    , m_spring(std::move(spring)) { }

void ExplicitLearnedSimulator::step(SpringState& state) {
  // The learned impulse m·Δv̂ of each spring, evaluated at the start of the step, summed at the
  // nodes; position is integrated once, by the semi-implicit update.
  const LearnedSpring& spring = m_spring;
  semi_implicit_step(state, [&spring](double e, double rate) { return spring.force(e, rate); });
}

// --- factory ---------------------------------------------------------------------------------

std::unique_ptr<SpringStepper> make_learned_simulator(SpringSystem system, LearnedSpring spring,
    const LearnedSimulatorOptions& options, const Loads& loads) {
  options.validate();
  const double dt = options.dt > 0.0 ? options.dt : spring.dt();
  switch (options.mode) {
  case LearnedMode::paper:
    return std::make_unique<PaperSimulator>(std::move(system), std::move(spring), dt, loads);
  case LearnedMode::corrected_explicit:
    return std::make_unique<ExplicitLearnedSimulator>(
        std::move(system), std::move(spring), dt, loads);
  case LearnedMode::corrected_implicit:
    return std::make_unique<ImplicitLearnedSimulator>(
        std::move(system), std::move(spring), dt, options, loads);
  }
  throw InternalError("unknown learned mode");
}

} // namespace elastolearn::springs
