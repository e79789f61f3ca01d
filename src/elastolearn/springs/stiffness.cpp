#include <elastolearn/springs/stiffness.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/reference_simulator.hpp>

#include <cmath>

namespace elastolearn::springs {

StepperFactory reference_factory(const SpringLaw& law, double dt) {
  return [law, dt](const SpringSystem& system) -> std::unique_ptr<SpringStepper> {
    return std::make_unique<ReferenceSimulator>(system, law, dt);
  };
}

StepperFactory learned_factory(
    const LearnedSpring& spring, const LearnedSimulatorOptions& options) {
  return [spring, options](const SpringSystem& system) {
    return make_learned_simulator(system, spring, options);
  };
}

void StiffnessOptions::validate() const {
  if (forces.empty())
    throw InputError("stiffness.forces", "needs at least one force");
  for (double f : forces)
    if (!(f > 0.0) || !std::isfinite(f))
      throw InputError("stiffness.forces", "forces must be > 0, got " + std::to_string(f));
  fixed_point.validate();
}

LoadCase rope_load_case(int nodes, double rest_length) {
  LoadCase lc { make_rope(nodes, rest_length), { nodes - 1 }, nodes - 1, Vec3::UnitX(),
    static_cast<double>(nodes - 1), { true, false, false } };
  return lc;
}

LoadCase cloth_load_case(int columns, int rows, double spacing) {
  ClothOptions o;
  o.columns = columns;
  o.rows = rows;
  o.spacing = spacing;
  o.plane = ClothPlane::vertical;
  o.pins = ClothPins::top_corners;
  LoadCase lc { make_cloth(o), cloth_bottom_row(o), (rows - 1) * columns + columns / 2,
    -Vec3::UnitY(), 1.0, { true, true, false } };
  return lc;
}

namespace {
Loads blend(const Loads& a, const Loads& b, double t) {
  Loads out;
  out.forces = (1.0 - t) * a.forces + t * b.forces;
  out.gravity = (1.0 - t) * a.gravity + t * b.gravity;
  return out;
}
} // namespace

FixedPointResult equilibrium_with_continuation(SpringStepper& stepper, const Loads& from,
    const Loads& to, SpringState& state, const FixedPointOptions& options) {
  const int n = stepper.system().node_count();
  Loads a = from, b = to;
  if (a.forces.rows() == 0)
    a.forces = Positions::Zero(n, 3);
  if (b.forces.rows() == 0)
    b.forces = Positions::Zero(n, 3);
  double t = 0.0, step = 1.0;
  FixedPointResult last;
  while (t < 1.0) {
    const double target = std::min(1.0, t + step);
    SpringState trial = state;
    stepper.set_loads(blend(a, b, target));
    last = solve_fixed_point(stepper, trial, options);
    if (last.converged) {
      state = std::move(trial);
      t = target;
      step = std::min(2.0 * step, 1.0);
    } else {
      step *= 0.5;
      if (step < 1.0 / 1024) {
        last.message = "load continuation failed at load factor " + std::to_string(target) + ": "
            + last.message;
        return last;
      }
    }
  }
  return last;
}

StiffnessMeasurement measure_stiffness(
    const StepperFactory& factory, const LoadCase& load, const StiffnessOptions& options) {
  options.validate();
  std::unique_ptr<SpringStepper> stepper = factory(load.system);
  const SpringSystem& sys = stepper->system();
  FixedPointOptions fp = options.fixed_point;
  fp.components = load.components;
  StiffnessMeasurement m;
  SpringState state = rest_state(sys);
  Loads previous;
  previous.forces = Positions::Zero(sys.node_count(), 3);
  for (double force : options.forces) {
    Loads loads;
    loads.forces = Positions::Zero(sys.node_count(), 3);
    for (int a : load.load_nodes)
      loads.forces.row(a) = force * load.direction.transpose();
    const FixedPointResult r = equilibrium_with_continuation(*stepper, previous, loads, state, fp);
    if (!r.converged) {
      m.converged = false;
      m.message = "force " + std::to_string(force) + ": " + r.message;
      break;
    }
    previous = loads;
    const double disp = (state.x.row(load.measure_node) - sys.rest.row(load.measure_node))
                            .dot(load.direction.transpose());
    m.forces.push_back(force);
    m.displacements.push_back(disp);
    m.stiffness.push_back(force / (disp / load.series));
  }
  if (!m.stiffness.empty()) {
    double sum = 0.0;
    for (double k : m.stiffness)
      sum += k;
    m.mean = sum / static_cast<double>(m.stiffness.size());
    double var = 0.0;
    for (double k : m.stiffness)
      var += (k - m.mean) * (k - m.mean);
    m.stddev = m.stiffness.size() > 1 ? std::sqrt(var / static_cast<double>(m.stiffness.size() - 1))
                                      : 0.0;
  }
  return m;
}

} // namespace elastolearn::springs
