// elastolearn springs learn | table | simulate | stability — phase-space regression springs
// (paper 004), reproduced and corrected. Parses, calls the springs layer, prints.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/io/springs_scene.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/springs/paper_tables.hpp>
#include <elastolearn/springs/stability.hpp>

#include <cmath>
#include <cstdio>

namespace {

using namespace elastolearn;
using namespace elastolearn::springs;

const std::vector<std::string> k_modes = { "paper", "explicit", "implicit" };

void print_fit(const LearnedSpring& spring) {
  std::printf("learned spring: %s features, dt = %g s, mass = %g kg, %d samples\n",
      std::string(to_string(spring.features().kind)).c_str(), spring.dt(), spring.mass(),
      spring.report().samples);
  std::vector<std::string> names = { "1" };
  for (const auto& n : spring.features().names())
    names.push_back(n);
  std::printf("  %-16s %22s %22s\n", "feature", "d_e coefficient", "d_v coefficient");
  for (std::size_t r = 0; r < names.size(); ++r)
    std::printf("  %-16s %22.15g %22.15g\n", names[r].c_str(), spring.coefficients()(r, 0),
        spring.coefficients()(r, 1));
  const FitReport& rep = spring.report();
  if (rep.r_squared.size() == 2)
    std::printf(
        "  R^2 = (%.15g, %.15g), rms residual = (%.3g, %.3g), max residual = (%.3g, %.3g)\n",
        rep.r_squared[0], rep.r_squared[1], rep.rms_residual[0], rep.rms_residual[1],
        rep.max_residual[0], rep.max_residual[1]);
}

// --- learn --------------------------------------------------------------------------------
struct LearnArgs {
  double k = 500, c = 0, dt = 0.01, mass = 1, k3 = 0, k_compression = -1, ridge = 0;
  std::string law = "linear", features = "polynomial", sampling = "trajectories", output;
  int degree = 1, knots = 11, steps = 400;
};

void add_learn(CLI::App& parent) {
  auto a = std::make_shared<LearnArgs>();
  auto* cmd = parent.add_subcommand(
      "learn", "Learn a spring from 1-D semi-implicit Euler data and save it");
  cmd->add_option("--k", a->k, "reference stiffness [N/m]")->capture_default_str();
  cmd->add_option("--c", a->c, "reference damping [N s/m]")->capture_default_str();
  cmd->add_option("--dt", a->dt, "time step [s]")->capture_default_str();
  cmd->add_option("--mass", a->mass, "particle mass [kg]")->capture_default_str();
  cmd->add_option("--law", a->law, "reference law: linear | cubic | bilinear")
      ->capture_default_str();
  cmd->add_option("--k3", a->k3, "cubic coefficient [N/m^3]");
  cmd->add_option("--k-compression", a->k_compression, "bilinear: stiffness in compression [N/m]");
  cmd->add_option("--features", a->features, "polynomial | spline")->capture_default_str();
  cmd->add_option("--degree", a->degree, "polynomial degree")->capture_default_str();
  cmd->add_option("--knots", a->knots, "spline knot count over the sampled elongations")
      ->capture_default_str();
  cmd->add_option("--ridge", a->ridge, "ridge penalty")->capture_default_str();
  cmd->add_option("--sampling", a->sampling, "trajectories | phase-grid")->capture_default_str();
  cmd->add_option("--steps", a->steps, "steps per trajectory / grid points per axis")
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output, "learned spring JSON")->required();
  cmd->callback([a] {
    check_command_paths({}, { { a->output, "learned spring output (-o)" } });
    TrainingOptions t;
    t.law.kind = spring_law_kind_from_string(a->law, "--law");
    t.law.k = a->k;
    t.law.c = a->c;
    t.law.k3 = a->k3;
    t.law.k_compression = a->k_compression >= 0 ? a->k_compression : a->k;
    t.dt = a->dt;
    t.mass = a->mass;
    t.sampling = sampling_kind_from_string(a->sampling, "--sampling");
    t.steps = a->steps;
    LearnOptions o;
    o.features.kind = feature_kind_from_string(a->features, "--features");
    o.features.degree = a->degree;
    if (o.features.kind == FeatureKind::spline)
      o.features.knots = uniform_knots(-0.5, 0.5, a->knots);
    o.ridge = a->ridge;
    const LearnedSpring spring = learn_spring(t, o);
    print_fit(spring);
    io::write_learned_spring(a->output, spring, &t.law);
    std::printf("wrote %s\n", a->output.c_str());
  });
}

// --- table --------------------------------------------------------------------------------
struct TableArgs {
  int table = 1;
  std::string mode = "paper";
};

double percent(double ours, double paper) {
  return 100.0 * (ours / paper - 1.0);
}

void print_table(const TableArgs& a) {
  ExperimentOptions o;
  o.simulation.mode = learned_mode_from_string(a.mode, "--mode");
  std::printf("Paper 004, Table %d — mode '%s' (dt = %g, m = %g, l = %g, c = %g; equilibrium = "
              "fixed point of "
              "the step map; forces 5..50)\n",
      a.table, a.mode.c_str(), o.dt, o.mass, o.rest_length, o.c);
  if (a.table == 1) {
    std::printf("%8s %12s %14s %10s %9s %14s\n", "k_MSM", "paper k_REG", "ours k_REG", "sigma",
        "diff %", "reference k");
    for (const Table1Row& r : reproduce_table1(o))
      std::printf("%8g %12.2f %14.4f %10.2g %+9.4f %14.6f%s\n", r.k, r.paper, r.learned.mean,
          r.learned.stddev, percent(r.learned.mean, r.paper), r.reference.mean,
          r.learned.converged ? "" : "  (not converged)");
  } else if (a.table == 2) {
    std::printf("%6s %8s %12s %14s %9s %14s\n", "nodes", "k_MSM", "paper k", "ours k", "diff %",
        "reference k");
    for (const Table2Row& r : reproduce_table2(o))
      std::printf("%6d %8g %12.2f %14.4f %+9.3f %14.6f%s\n", r.nodes, r.k, r.paper, r.learned.mean,
          percent(r.learned.mean, r.paper), r.reference.mean,
          r.learned.converged ? "" : "  (not converged)");
  } else {
    std::printf("%8s | %10s %10s %8s | %12s %12s %8s | %9s\n", "k", "paper MSM", "paper REG",
        "ratio", "ours ref", "ours learned", "ratio", "ratio diff %");
    for (const Table3Row& r : reproduce_table3(o))
      std::printf("%8g | %10.3f %10.3f %8.4f | %12.4f %12.4f %8.4f | %+9.2f%s\n", r.k,
          r.paper_reference, r.paper_learned, r.paper_ratio(), r.reference.mean, r.learned.mean,
          r.ratio(), percent(r.ratio(), r.paper_ratio()),
          r.learned.converged ? "" : "  (not converged)");
    std::printf(
        "(the paper's absolute k_MSM use an unstated normalisation; the ratio is comparable)\n");
  }
}

void add_table(CLI::App& parent) {
  auto a = std::make_shared<TableArgs>();
  auto* cmd = parent.add_subcommand("table", "Print the paper's Table 1, 2 or 3 next to ours");
  cmd->add_option("table", a->table, "1 | 2 | 3")->required()->check(CLI::Range(1, 3));
  cmd->add_option("--mode", a->mode, "paper | explicit | implicit")
      ->check(CLI::IsMember(k_modes))
      ->capture_default_str();
  cmd->callback([a] { print_table(*a); });
}

// --- simulate -----------------------------------------------------------------------------
struct SimulateArgs {
  std::string scene, output, vtu, mode;
  int steps = 0;
  bool quiet = false;
};

void add_simulate(CLI::App& parent) {
  auto a = std::make_shared<SimulateArgs>();
  auto* cmd
      = parent.add_subcommand("simulate", "Simulate a rope/cloth scene; write HDF5 (and VTU/PVD)");
  cmd->add_option("scene", a->scene, "springs scene (elastolearn-springs-scene/1 JSON)")
      ->required();
  cmd->add_option(
      "-o,--output", a->output, "trajectory HDF5 (default: the scene's output.trajectory)");
  cmd->add_option("--vtu", a->vtu, "also write a VTU per frame + PVD into this folder");
  cmd->add_option("--mode", a->mode, "override the mode: reference | paper | explicit | implicit");
  cmd->add_option("--steps", a->steps, "override the number of steps");
  cmd->add_flag("-q,--quiet", a->quiet, "no progress line");
  cmd->callback([a] {
    io::SpringsScene scene = io::read_springs_scene(a->scene);
    if (!a->mode.empty()) {
      scene.reference = a->mode == "reference";
      if (!scene.reference)
        scene.simulation.mode = learned_mode_from_string(a->mode, "--mode");
    }
    if (a->steps > 0)
      scene.steps = a->steps;
    std::filesystem::path output = !a->output.empty() ? std::filesystem::path(a->output)
        : scene.trajectory                            ? *scene.trajectory
                                                      : std::filesystem::path();
    if (output.empty())
      throw InputError(a->scene, "no output: give -o FILE.h5 or output.trajectory in the scene");
    std::optional<std::filesystem::path> vtu = scene.vtu_directory;
    if (!a->vtu.empty())
      vtu = a->vtu;
    std::vector<CommandOutput> outputs = { { output, "trajectory output" } };
    if (vtu) {
      outputs.push_back({ *vtu, "ParaView folder", OutputKind::folder });
      outputs.push_back({ *vtu / (output.stem().string() + ".pvd"), "ParaView series" });
    }
    check_command_paths(scene.inputs, outputs);
    auto stepper = io::make_scene_stepper(scene);
    std::printf("%s: %d nodes, %d springs, mode %s, dt %g s, %d steps\n", scene.name.c_str(),
        scene.system.node_count(), scene.system.spring_count(),
        std::string(stepper->name()).c_str(), stepper->dt(), scene.steps);
    const auto start = Clock::now();
    const SimulationRecord record = run_simulation(*stepper, rest_state(scene.system), scene.steps,
        scene.every, a->quiet ? ProgressCallback {} : terminal_progress("springs"));
    const double seconds = seconds_since(start);
    io::TrajectoryData data = io::springs_trajectory(scene.system, record);
    data.metadata["scene"] = a->scene;
    data.metadata["mode"] = std::string(stepper->name());
    data.metadata["dt"] = std::to_string(stepper->dt());
    io::write_trajectory_h5(output, data);
    std::printf("%s after %d steps (%.3f s, %.1f steps/s); wrote %s (%zu frames)\n",
        record.message.c_str(), record.steps_done, seconds,
        record.steps_done / std::max(seconds, 1e-9), output.c_str(), data.positions.size());
    if (vtu)
      std::printf("wrote %s\n", io::write_vtu_series(*vtu, output.stem().string(), data).c_str());
    if (record.diverged)
      throw InputError(a->scene, record.message);
  });
}

// --- stability ----------------------------------------------------------------------------
struct StabilityArgs {
  double k_min = 10, k_max = 1e7;
  int steps = 500;
  bool quick = false;
};

void add_stability(CLI::App& parent) {
  auto a = std::make_shared<StabilityArgs>();
  auto* cmd
      = parent.add_subcommand("stability", "Largest stable k per mode and system (dt = 0.01)");
  cmd->add_option("--k-min", a->k_min, "lower end of the search [N/m]")->capture_default_str();
  cmd->add_option("--k-max", a->k_max, "upper end of the search [N/m]")->capture_default_str();
  cmd->add_option("--steps", a->steps, "steps per run")->capture_default_str();
  cmd->add_flag("--quick", a->quick, "skip the 25x25 cloth");
  cmd->callback([a] {
    StabilityOptions so;
    so.k_min = a->k_min;
    so.k_max = a->k_max;
    so.steps = a->steps;
    std::vector<StabilityCase> cases
        = { single_spring_case(), rope_case(10), hanging_cloth_case(5) };
    if (!a->quick)
      cases.push_back(hanging_cloth_case(25));
    const ExperimentOptions eo;
    std::printf("largest stable k [N/m] over %d steps at dt = %g (bracket: stable .. unstable)\n",
        so.steps, eo.dt);
    std::printf("%-14s %-10s %14s %14s\n", "system", "mode", "stable", "unstable");
    for (const StabilityCase& test : cases)
      for (const std::string mode : { "reference", "paper", "explicit", "implicit" }) {
        std::function<StepperFactory(double)> model = [&](double k) -> StepperFactory {
          SpringLaw law;
          law.k = k;
          if (mode == "reference")
            return reference_factory(law, eo.dt);
          LearnedSimulatorOptions o;
          o.mode = learned_mode_from_string(mode, "mode");
          return learned_factory(learn_paper_spring(k, eo), o);
        };
        const StabilityResult r = find_stability_limit(model, test, so);
        std::printf("%-14s %-10s %14.4g %14.4g%s\n", test.name.c_str(), mode.c_str(),
            r.largest_stable, r.smallest_unstable,
            std::isinf(r.smallest_unstable) ? "  (stable at k-max)" : "");
        std::fflush(stdout);
      }
  });
}

void add_springs_command(CLI::App& root) {
  auto* cmd = root.add_subcommand(
      "springs", "Mass-spring ropes and cloth with springs learned in phase space (paper 004)");
  cmd->require_subcommand(1);
  add_learn(*cmd);
  add_table(*cmd);
  add_simulate(*cmd);
  add_stability(*cmd);
}

} // namespace

ELASTOLEARN_COMMAND(60, add_springs_command)
