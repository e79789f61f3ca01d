#pragma once
/// \file Stiffness measurement as in paper 004 §4–5: apply forces 5…50 (step 5), find the
/// equilibrium of the simulator's own step map, and report F/e (mean and σ over the forces).
#include <elastolearn/springs/fixed_point.hpp>
#include <elastolearn/springs/learned_simulator.hpp>
#include <elastolearn/springs/spring_law.hpp>

#include <functional>
#include <memory>

namespace elastolearn::springs {

/// Builds a simulator for a system (the model under test: reference or learned in some mode).
using StepperFactory = std::function<std::unique_ptr<SpringStepper>(const SpringSystem&)>;

/// Factory of reference semi-implicit Euler simulators with `law` and step `dt`.
StepperFactory reference_factory(const SpringLaw& law, double dt);
/// Factory of learned simulators (paper / explicit / implicit) driven by `spring`.
StepperFactory learned_factory(const LearnedSpring& spring, const LearnedSimulatorOptions& options);

/// Options of the stiffness measurements.
struct StiffnessOptions {
  std::vector<double> forces = { 5, 10, 15, 20, 25, 30, 35, 40, 45, 50 }; ///< [N] (paper §4)
  FixedPointOptions fixed_point;
  /// Throws InputError("stiffness.forces", ...) for an empty list or non-positive forces.
  void validate() const;
};

/// One stiffness measurement: per force the measured displacement and F/displacement·series.
struct StiffnessMeasurement {
  std::vector<double> forces; ///< [N]
  std::vector<double> displacements; ///< measured displacement along the force [m]
  std::vector<double> stiffness; ///< per force [N/m]
  double mean = 0.0; ///< mean stiffness [N/m]
  double stddev = 0.0; ///< sample standard deviation [N/m]
  bool converged = true; ///< every equilibrium converged
  std::string message; ///< why not, if not
};

/// A loaded structure: forces `direction`·F on `load_nodes`, displacement of `measure_node`
/// along `direction`, stiffness = F / (displacement / series) (series = springs in series).
struct LoadCase {
  SpringSystem system;
  std::vector<int> load_nodes;
  int measure_node = 0;
  Vec3 direction = Vec3::UnitX();
  double series = 1.0;
  std::array<bool, 3> components = { true, true, true }; ///< unknowns of the fixed point
};

/// Rope of `nodes` nodes (paper §4, Table 2): node 0 fixed, force on the last node along the
/// rope; series = nodes − 1. `nodes` = 2 is the single spring of Table 1.
LoadCase rope_load_case(int nodes, double rest_length = 1.0);
/// 5×5-style cloth of paper §5 (Table 3): vertical, top corners pinned, force down on each
/// bottom-row node, displacement of the bottom-row centre node.
LoadCase cloth_load_case(int columns = 5, int rows = 5, double spacing = 1.0);

/// Measure: for each force (continuation from the previous equilibrium, with the load step
/// halved where Newton fails) find the fixed point and record the displacement.
StiffnessMeasurement measure_stiffness(
    const StepperFactory& factory, const LoadCase& load, const StiffnessOptions& options = {});

/// Equilibrium of `stepper` under `loads`, reached from `state` by load continuation (the
/// load factor goes 0 → 1, halving steps on failure). Returns the fixed-point result of the last
/// solve; `state` holds the equilibrium when it converged.
FixedPointResult equilibrium_with_continuation(SpringStepper& stepper, const Loads& from,
    const Loads& to, SpringState& state, const FixedPointOptions& options);

} // namespace elastolearn::springs
