// elastolearn fit-parameters (scene.json --observations obs.h5 | training.json) -o fitted.json
//                           [--frames N]
//                           [--fit young,poisson,alpha0,alpha1] [--max-iterations K] [--tolerance
//                           T]
// The parameter-fitting baseline (paper 000's reference [14]): fit E, ν, α₀, α₁ of the scene's
// nominal material to the observations (of one scene, or of every motion of a training set at
// once) and write them as a material file. docs/learning.md
// "Parameter-fitting baseline".
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/nominal_parameters.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/learn/parameter_fit.hpp>

#include <cstdio>

namespace {

using namespace elastolearn;

struct FitOptions {
  std::string scene, observations, output;
  std::string fit = "young,poisson,alpha0,alpha1";
  learn::ParameterFitOptions library;
  bool serial = false;
  bool quiet = false;
};

/// What is fitted: one scene and its observations, or every motion of a training set.
struct FitData {
  std::vector<learn::Motion> motions;
  io::MaterialFile fitted; ///< the nominal material (scene format) the parameters go into
  std::string material_source; ///< names that material in messages
  std::vector<CommandInput> inputs;
};

FitData read_fit_data(const FitOptions& o) {
  FitData d;
  if (io::is_training_set_file(o.scene)) {
    // A training set: one fit to all its motions (learn::fit_parameters over motions), as the
    // best single homogeneous material for all of them.
    if (!o.observations.empty())
      throw InputError("--observations",
          "not with a training set, which names its observation files (" + o.scene + ")");
    io::TrainingSet set = io::read_training_set(o.scene);
    d.motions = std::move(set.motions);
    d.fitted.material = std::move(set.nominal_material);
    d.material_source = set.files.front().paths.scene.string();
    d.inputs = std::move(set.inputs);
    return d;
  }
  if (o.observations.empty())
    throw InputError("--observations", "is required with a scene file (or give a training set)");
  const io::SceneFile scene_file = io::read_scene_file(o.scene);
  const sim::Scene& scene = scene_file.scene;
  d.inputs = scene_file.inputs;
  d.inputs.push_back({ o.observations, "observations (--observations)" });
  if (scene.material.stiffness_scale)
    throw InputError(o.scene,
        "material.regions: fit-parameters fits one homogeneous material; the scene's is "
        "heterogeneous");
  if (scene.material.correction)
    throw InputError(o.scene,
        "material: the scene's material carries a correction; fit-parameters fits a nominal one");
  const nlohmann::json root = io::read_json_file(o.scene);
  d.fitted = io::scene_material(io::JsonObject(root, o.scene), scene_file.path.parent_path());
  d.material_source
      = root.at("material").is_string() ? root.at("material").get<std::string>() : o.scene;
  observe::Observation observed = io::read_observation_h5(o.observations);
  observed.validate(scene.mesh.num_vertices(), scene.frames + 1, scene.dt, o.observations);
  d.motions.push_back({ o.observations, scene, std::move(observed) });
  return d;
}

void run_fit(const FitOptions& o) {
  FitData data = read_fit_data(o);
  check_command_paths(data.inputs, { { o.output, "fitted material output (-o)" } });
  io::MaterialFile& fitted = data.fitted;
  material::ElasticModelType type {};
  const learn::NominalParameters start = io::nominal_parameters_from_json(
      io::JsonObject(fitted.material, data.material_source, "material"), type);
  learn::ParameterFitOptions options = o.library;
  options.parameters = learn::fit_parameters_from_string(o.fit, "--fit");
  options.parallel = !o.serial;
  options.validate();

  const sim::Scene& scene = data.motions.front().scene;
  const double diagonal = scene.mesh.bounding_box_diagonal();
  int observed_vertices = 0;
  for (const learn::Motion& m : data.motions) {
    const std::string lost = observe::describe_lost_entries(m.observed);
    std::printf("fitting %s of %s: %d vertices, %d tets, %d of %d frames (dt = %g s), %d "
                "observed vertices%s, %s nominal\n",
        o.fit.c_str(), m.scene.name.c_str(), m.scene.mesh.num_vertices(), m.scene.mesh.num_tets(),
        options.frames < 0 ? m.scene.frames : options.frames, m.scene.frames, m.scene.dt,
        m.observed.num_observed(), lost.empty() ? "" : (" (" + lost + ")").c_str(),
        material::to_string(type).c_str());
    observed_vertices += m.observed.num_observed();
  }
  std::fflush(stdout);
  const ProgressCallback progress = [&](long, long, const std::string& line) {
    if (o.quiet)
      return;
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  const learn::ParameterFitReport report = data.motions.size() == 1
      ? learn::fit_parameters(scene, type, start, data.motions.front().observed, options, progress)
      : learn::fit_parameters(data.motions, type, start, options, progress);
  if (report.stop == learn::FitStop::StartDiverged) {
    std::fprintf(stderr, "elastolearn: error: %s\n", report.message.c_str());
    throw CLI::RuntimeError(1);
  }

  fitted.material = io::with_nominal_parameters(
      fitted.material, report.fitted, o.fit.find("alpha") != std::string::npos);
  nlohmann::json history = nlohmann::json::array();
  for (const auto& it : report.history)
    history.push_back({ { "iteration", it.iteration }, { "parameters", io::to_json(it.parameters) },
        { "rms_error_m", it.rms_error }, { "max_error_m", it.max_error }, { "lambda", it.lambda },
        { "rejected_steps", it.rejected_steps }, { "seconds", it.seconds } });
  nlohmann::json fitted_names = nlohmann::json::array();
  for (auto p : options.parameters)
    fitted_names.push_back(learn::to_string(p));
  fitted.training = { { "method", "parameter_fit" }, { "scene", o.scene },
    { "observations", o.observations }, { "observed_vertices", observed_vertices },
    { "motions", data.motions.size() }, { "fitted", fitted_names }, { "frames", report.frames },
    { "initial", io::to_json(report.initial) }, { "final", io::to_json(report.fitted) },
    { "initial_rms_error_m", report.initial_rms }, { "initial_max_error_m", report.initial_max },
    { "final_rms_error_m", report.final_rms }, { "final_max_error_m", report.final_max },
    { "iterations", report.iterations }, { "simulations", report.simulations },
    { "diverged_simulations", report.diverged }, { "unheld_initial_loads", report.unheld_loads },
    { "seconds", report.seconds }, { "stop", learn::to_string(report.stop) },
    { "message", report.message }, { "history", history } };
  io::write_material_file(o.output, fitted);

  std::printf("%s: %s\n", learn::to_string(report.stop).c_str(), report.message.c_str());
  std::printf(
      "observation error rms %.4g %% -> %.4g %%, max %.4g %% -> %.4g %% of the size (%.4g m); "
      "%d iterations, %d simulations (%d failed, %d of them in the initial load's static "
      "solve), %.1f s\n",
      100 * report.initial_rms / diagonal, 100 * report.final_rms / diagonal,
      100 * report.initial_max / diagonal, 100 * report.final_max / diagonal, diagonal,
      report.iterations, report.simulations, report.diverged, report.unheld_loads, report.seconds);
  std::printf("fitted: E %.6g Pa, nu %.5g, alpha0 %.5g 1/s, alpha1 %.5g s\n", report.fitted.young,
      report.fitted.poisson, report.fitted.alpha0, report.fitted.alpha1);
  std::printf("material: %s\n", o.output.c_str());
  if (report.stop == learn::FitStop::Interrupted) {
    std::fprintf(stderr, "elastolearn: interrupted; wrote the best parameters so far\n");
    throw CLI::RuntimeError(130);
  }
}

void add_fit_parameters_command(CLI::App& root) {
  auto o = std::make_shared<FitOptions>();
  auto* cmd = root.add_subcommand("fit-parameters",
      "Fit E, nu and Rayleigh damping of the nominal material to observations (the baseline of "
      "learn)");
  cmd->add_option("scene", o->scene,
         "scene with the start material (elastolearn-scene/1 JSON), or a training set "
         "(elastolearn-training/1: one fit to all its motions)")
      ->required();
  cmd->add_option("--observations", o->observations,
      "observation HDF5 (from observe, or your capture); not with a training set");
  cmd->add_option(
         "-o,--output", o->output, "material JSON to write (fitted nominal, no correction)")
      ->required();
  cmd->add_option(
         "--fit", o->fit, "comma-separated parameters to fit: young, poisson, alpha0, alpha1")
      ->capture_default_str();
  auto& l = o->library;
  cmd->add_option("--frames", l.frames, "fit the first N steps only (faster; default: all)");
  cmd->add_option("--max-iterations", l.max_iterations, "Levenberg-Marquardt iterations")
      ->capture_default_str();
  cmd->add_option("--tolerance", l.tolerance, "stop below this relative improvement")
      ->capture_default_str();
  cmd->add_option("--fd-step", l.finite_difference_step,
         "finite-difference step in log E, logit nu, log alpha")
      ->capture_default_str();
  cmd->add_flag("--serial", o->serial, "run the finite-difference simulations one after the other");
  cmd->add_flag("-q,--quiet", o->quiet, "no per-iteration lines");
  cmd->callback([o] { run_fit(*o); });
}

} // namespace

ELASTOLEARN_COMMAND(37, add_fit_parameters_command)
