#pragma once
/// \file Mass-spring simulators driven by a learned spring (paper 004 §2, §5) — the learned
/// spring is their only spring model. Three modes:
/// - paper: the paper's scheme, faithfully: a semi-implicit Euler step with external forces
///   only, then each spring's predicted (Δe, Δv) applied along the spring and averaged over the
///   node's springs (§6). It integrates position twice and scales loads by the node degree.
/// - explicit: corrected. The learned Δv is the spring's impulse m·Δv̂ (force f = m·Δv̂/dt),
///   summed (not averaged) at each node, followed by one semi-implicit Euler update. Equals the
///   reference semi-implicit Euler system up to the regression's round-off.
/// - implicit: corrected, stiff. Backward Euler linearised once per step with the learned
///   spring's slopes (see implicit_simulator.hpp).
#include <elastolearn/springs/explicit_stepper.hpp>
#include <elastolearn/springs/learned_spring.hpp>

#include <memory>
#include <string>
#include <string_view>

namespace elastolearn::springs {

/// Mode of a learned simulator; one name table for CLI and JSON: "paper", "explicit", "implicit".
enum class LearnedMode { paper, corrected_explicit, corrected_implicit };
std::string_view to_string(LearnedMode mode);
/// Inverse of to_string; throws InputError(where, ...).
LearnedMode learned_mode_from_string(const std::string& name, const std::string& where);

/// Linear solver of the implicit mode: "auto" (direct up to `direct_max_dofs`), "direct"
/// (Eigen SimplicialLDLT, symbolic analysis once), "cg" (block-Jacobi PCG, warm started).
enum class LinearSolverKind { automatic, direct, cg };
std::string_view to_string(LinearSolverKind kind);
LinearSolverKind linear_solver_from_string(const std::string& name, const std::string& where);

/// Options of a learned simulator.
struct LearnedSimulatorOptions {
  LearnedMode mode = LearnedMode::corrected_explicit;
  double dt = 0.0; ///< [s]; 0 = the learned spring's training dt (paper mode requires it)
  LinearSolverKind solver = LinearSolverKind::automatic; ///< implicit mode only
  double cg_tolerance = 1e-10; ///< relative residual ‖r‖/‖b‖
  int cg_max_iterations = 2000;
  int direct_max_dofs = 20000; ///< "auto" uses the direct solver up to this many unknowns
  /// Throws InputError("simulation.<field>", ...).
  void validate() const;
};

/// The paper's learned simulator (§2, §6): see the file comment.
class PaperSimulator final : public ExplicitStepper {
  public:
  /// Throws InputError if dt differs from the spring's training dt (the learned map is a map
  /// over exactly one training step) or loads are malformed.
  PaperSimulator(SpringSystem system, LearnedSpring spring, double dt, const Loads& loads = {});
  void step(SpringState& state) override;
  std::string_view name() const override { return "paper"; }

  private:
  LearnedSpring m_spring;
  Positions m_spring_dx, m_spring_dv, m_node_dx, m_node_dv; // scratch
};

/// Corrected explicit learned simulator: see the file comment.
class ExplicitLearnedSimulator final : public ExplicitStepper {
  public:
  /// Throws InputError for dt ≤ 0 or malformed loads.
  ExplicitLearnedSimulator(
      SpringSystem system, LearnedSpring spring, double dt, const Loads& loads = {});
  void step(SpringState& state) override;
  std::string_view name() const override { return "explicit"; }

  private:
  LearnedSpring m_spring;
};

/// Build the simulator of `options.mode`. Throws InputError for invalid options.
std::unique_ptr<SpringStepper> make_learned_simulator(SpringSystem system, LearnedSpring spring,
    const LearnedSimulatorOptions& options, const Loads& loads = {});

} // namespace elastolearn::springs
