// The commands as functions: simulate, observe, learn, evaluate. Each calls the library function
// its CLI command calls (io::simulate_to_files / io::simulate_trajectory, io::observe_trajectory,
// learn::learn_material + io::learned_material_file, io::evaluate_material) with the GIL
// released while it computes.
#include "arrays.hpp"
#include "objects.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/evaluation_report.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learned_material.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/io/learning_run_report.hpp>
#include <elastolearn/io/material_evaluation.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/report_resources.hpp>
#include <elastolearn/io/scene_output.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/io/trajectory_observation.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <functional>
#include <optional>

namespace elastolearn::python {

namespace {

/// What simulate returns: the recorded trajectory and the run's report.
struct Simulation {
  io::TrajectoryData trajectory;
  sim::SimulationReport report;
};

Simulation simulate(const py::handle& scene_arg, std::optional<int> frames,
    const py::handle& material, std::optional<std::string> solver,
    std::optional<std::filesystem::path> output, int every, bool progress) {
  io::SceneFile file = scene_argument(scene_arg);
  sim::Scene& scene = file.scene;
  if (solver)
    scene.linear_solver = sim::linear_solver_type_from_string(*solver);
  if (frames) {
    if (*frames < 1)
      throw InputError("frames", "must be at least 1, got " + std::to_string(*frames));
    scene.frames = *frames;
  }
  if (every < 1)
    throw InputError("every", "must be at least 1, got " + std::to_string(every));
  if (!material.is_none())
    scene.material = material_argument(material).model;
  const ProgressCallback callback = progress ? terminal_progress("simulate") : ProgressCallback {};
  Simulation result;
  if (output) {
    std::vector<CommandInput> inputs = file.inputs;
    if (!material.is_none()) {
      std::string path;
      if (is_path(material, path))
        inputs.push_back({ path, "material" });
    }
    check_command_paths(inputs, { { *output, "trajectory output" } });
    {
      py::gil_scoped_release release;
      io::SceneOutputOptions out;
      out.trajectory = *output;
      out.every = every;
      result.report = io::simulate_to_files(scene, out, callback);
    }
    if (result.report.frames_written > 0)
      result.trajectory = io::read_trajectory_h5(*output);
  } else {
    py::gil_scoped_release release;
    result.trajectory = io::simulate_trajectory(scene, every, callback, result.report);
  }
  if (!result.report.completed) {
    const std::string warning
        = "elastolearn.simulate: " + result.report.message + " (the frames before it are kept)";
    if (PyErr_WarnEx(PyExc_RuntimeWarning, warning.c_str(), 1) < 0)
      throw py::error_already_set(); // warnings configured as errors
  }
  return result;
}

template <typename T> T value(const py::handle& v, const std::string& name) {
  try {
    return v.cast<T>();
  } catch (const py::cast_error&) {
    throw InputError(name, "has the wrong type (" + std::string(py::str(py::type::of(v))) + ")");
  }
}

Observation observe(const py::handle& trajectory, std::optional<double> visible_fraction,
    const py::handle& vertices, bool all_vertices, const py::handle& onto, double noise,
    double dropout, double dropout_burst, std::uint64_t seed,
    std::optional<std::filesystem::path> output) {
  if (int(visible_fraction.has_value()) + int(!vertices.is_none()) + int(all_vertices) != 1)
    throw InputError(
        "observe", "give exactly one of visible_fraction, vertices and all_vertices=True");
  std::vector<CommandInput> inputs;
  io::ObservationRequest request;
  request.all_vertices = all_vertices;
  // observe --onto: the vertices of another mesh (a scene), embedded in the trajectory's.
  std::optional<io::SceneFile> onto_scene;
  if (!onto.is_none()) {
    onto_scene = scene_argument(onto);
    for (const CommandInput& input : onto_scene->inputs)
      inputs.push_back({ input.path, input.role + " (onto)" });
    request.onto = &onto_scene->scene.mesh;
    std::string path;
    if (is_path(onto, path))
      request.onto_source = path;
  }
  std::string vertex_file;
  if (is_path(vertices, vertex_file)) {
    inputs.push_back({ vertex_file, "vertex list (vertices)" });
    request.vertices = io::read_vertex_id_list(vertex_file);
    request.vertices_source = vertex_file;
  } else if (!vertices.is_none()) {
    request.vertices = to_ints(value<IntArray>(vertices, "vertices"), "vertices");
  }
  request.visible_fraction = visible_fraction.value_or(0);
  request.noise = noise;
  request.seed = seed;
  request.dropout = dropout;
  request.dropout_burst = dropout_burst;
  std::string source;
  const io::TrajectoryData data = trajectory_argument(trajectory, source);
  if (source != "trajectory")
    inputs.push_back({ source, "trajectory" });
  if (output)
    check_command_paths(inputs, { { *output, "observation output" } });
  Observation result;
  {
    py::gil_scoped_release release;
    io::TrajectoryObservation observed = io::observe_trajectory(data, source, request);
    result.observation = std::move(observed.observation);
    result.metadata = std::move(observed.metadata);
    if (output)
      io::write_observation_h5(*output, result.observation, result.metadata);
  }
  return result;
}

/// learn's keyword options: name → how it sets the recipe's options (the CLI flags' names with
/// underscores, in --help's order; a flag is a bool; docs/python.md lists them).
struct LearnSettings {
  learn::RecipeOptions recipe;
};

using Setter = std::function<void(LearnSettings&, const py::handle&)>;

const std::vector<std::pair<std::string, Setter>>& learn_option_table() {
  using S = LearnSettings;
  using H = const py::handle&;
  static const std::vector<std::pair<std::string, Setter>> table = {
    { "noise", [](S& s, H v) { s.recipe.noise = v.is_none() ? -1.0 : value<double>(v, "noise"); } },
    { "validation_fraction",
        [](S& s, H v) { s.recipe.validation_fraction = value<double>(v, "validation_fraction"); } },
    { "no_parameter_fit",
        [](S& s, H v) { s.recipe.fit_parameters = !value<bool>(v, "no_parameter_fit"); } },
    { "parameter_fit_iterations",
        [](S& s, H v) {
          s.recipe.parameter_fit.max_iterations = value<int>(v, "parameter_fit_iterations");
        } },
    { "max_iterations",
        [](S& s, H v) { s.recipe.loop.max_iterations = value<int>(v, "max_iterations"); } },
    { "patience", [](S& s, H v) { s.recipe.loop.patience = value<int>(v, "patience"); } },
    { "free_halvings",
        [](S& s, H v) { s.recipe.loop.free_halvings = value<int>(v, "free_halvings"); } },
    { "no_backtrack",
        [](S& s, H v) { s.recipe.loop.backtrack = !value<bool>(v, "no_backtrack"); } },
    { "no_stability_cuts",
        [](S& s, H v) {
          const bool cuts = !value<bool>(v, "no_stability_cuts");
          s.recipe.loop.stability_cuts = cuts;
          s.recipe.loop.forward_fit.stability_cuts = cuts;
        } },
    { "modes", [](S& s, H v) { s.recipe.loop.pod.max_modes = value<int>(v, "modes"); } },
    { "pod_stride",
        [](S& s, H v) { s.recipe.loop.pod.frame_stride = value<int>(v, "pod_stride"); } },
    { "full_space", [](S& s, H v) { s.recipe.loop.full_space = value<bool>(v, "full_space"); } },
    { "pod_forward_only",
        [](S& s, H v) {
          s.recipe.loop.pod_with_constrained = !value<bool>(v, "pod_forward_only");
        } },
    { "kernels", [](S& s, H v) { s.recipe.loop.centres = value<int>(v, "kernels"); } },
    { "position_weight",
        [](S& s, H v) {
          s.recipe.loop.space_time.position_weight = value<double>(v, "position_weight");
        } },
    { "space_time_iterations",
        [](S& s, H v) {
          s.recipe.loop.space_time.max_iterations = value<int>(v, "space_time_iterations");
        } },
    { "regularization",
        [](S& s, H v) { s.recipe.loop.rbf.regularization = value<double>(v, "regularization"); } },
    { "reconstruction",
        [](S& s, H v) {
          s.recipe.loop.reconstruction.method = learn::reconstruction_method_from_name(
              value<std::string>(v, "reconstruction"), "reconstruction");
        } },
    { "frame_stride",
        [](S& s, H v) {
          s.recipe.loop.reconstruction.frame_stride = value<int>(v, "frame_stride");
        } },
    { "unprojected_reconstruction",
        [](S& s, H v) {
          s.recipe.loop.projected_reconstruction = !value<bool>(v, "unprojected_reconstruction");
        } },
    { "full_space_weight",
        [](S& s, H v) {
          s.recipe.loop.reconstruction.full_space_weight = value<double>(v, "full_space_weight");
        } },
    { "no_damping",
        [](S& s, H v) { s.recipe.loop.rbf.fit_damping = !value<bool>(v, "no_damping"); } },
    { "linear_tail",
        [](S& s, H v) { s.recipe.loop.rbf.quadratic_tail = !value<bool>(v, "linear_tail"); } },
    { "damping_regularization",
        [](S& s, H v) {
          s.recipe.loop.rbf.damping_regularization = value<double>(v, "damping_regularization");
        } },
    { "continuation",
        [](S& s, H v) {
          s.recipe.loop.rbf.continuation = material::continuation_from_name(
              value<std::string>(v, "continuation"), "continuation");
        } },
    { "smoothness",
        [](S& s, H v) { s.recipe.loop.rbf.smoothness = value<double>(v, "smoothness"); } },
    { "seed", [](S& s, H v) { s.recipe.loop.seed = value<std::uint64_t>(v, "seed"); } },
    { "forward_fit_tolerance",
        [](S& s, H v) {
          s.recipe.loop.forward_fit.function_tolerance = value<double>(v, "forward_fit_tolerance");
        } },
    { "forward_fit",
        [](S& s, H v) {
          s.recipe.loop.forward_fit.max_iterations = value<int>(v, "forward_fit");
        } },
    { "damping_prior",
        [](S& s, H v) {
          s.recipe.loop.forward_fit.damping_prior = value<double>(v, "damping_prior");
        } },
    { "elastic_prior",
        [](S& s, H v) {
          s.recipe.loop.forward_fit.elastic_prior = value<double>(v, "elastic_prior");
        } },
    { "kernel_smoothing",
        [](S& s, H v) { s.recipe.loop.rbf.epsilon = value<double>(v, "kernel_smoothing"); } },
    { "stress_kernels",
        [](S& s, H v) { s.recipe.loop.rbf.energy_kernels = !value<bool>(v, "stress_kernels"); } },
    { "no_neo_hookean_tail",
        [](S& s, H v) {
          s.recipe.loop.rbf.neo_hookean_tail = !value<bool>(v, "no_neo_hookean_tail");
        } },
    { "no_mass_damping",
        [](S& s, H v) { s.recipe.loop.rbf.mass_damping = !value<bool>(v, "no_mass_damping"); } },
    { "damping_quadratic_tail",
        [](S& s, H v) {
          s.recipe.loop.rbf.damping_quadratic_tail = value<bool>(v, "damping_quadratic_tail");
        } },
    { "allow_rest_stress",
        [](S& s, H v) {
          s.recipe.loop.rbf.stress_free_rest = !value<bool>(v, "allow_rest_stress");
        } },
    { "no_network", [](S& s, H v) { s.recipe.network.enabled = !value<bool>(v, "no_network"); } },
    { "network_kind",
        [](S& s, H v) {
          s.recipe.network.kind = learn::network_kind_from_name(
              value<std::string>(v, "network_kind"), "network_kind");
        } },
    { "network_rate_jitter",
        [](S& s, H v) {
          s.recipe.network.samples.rate_jitter = value<double>(v, "network_rate_jitter");
        } },
    { "network_motion_scales",
        [](S& s, H v) {
          s.recipe.network.motion_scales = value<std::vector<double>>(v, "network_motion_scales");
        } },
    { "network_samples",
        [](S& s, H v) {
          s.recipe.network.samples.recorded_samples = value<int>(v, "network_samples");
        } },
  };
  return table;
}

LearnSettings learn_settings(const py::kwargs& options) {
  LearnSettings s;
  const auto& table = learn_option_table();
  for (const auto& [key, v] : options) {
    const std::string name = py::str(key);
    const auto it = std::find_if(
        table.begin(), table.end(), [&](const auto& entry) { return entry.first == name; });
    if (it == table.end()) {
      std::string known;
      for (const auto& entry : table)
        known += (known.empty() ? "" : ", ") + entry.first;
      throw py::type_error("learn() got an unknown option '" + name + "' (options: " + known + ")");
    }
    it->second(s, v);
  }
  s.recipe.validate();
  return s;
}

/// One line per loop iteration for `verbose` (the CLI prints a fuller table).
std::string iteration_line(const learn::IterationRecord& r, double size) {
  char line[256];
  const learn::ForwardOutcome& forward = learn::forward_of(r);
  if (!forward.completed())
    std::snprintf(line, sizeof line, "iteration %d: forward simulation %s (%s)",
        learn::iteration_of(r),
        forward.status() == learn::ForwardStatus::unstable ? "skipped, unstable" : "diverged",
        forward.message().c_str());
  else
    std::snprintf(line, sizeof line,
        "iteration %d%s: error rms %.4f %%, max %.4f %% of the size; %.1f s",
        learn::iteration_of(r), learn::forward_fit_of(r) ? " (forward fit)" : "",
        100 * forward.error().rms / size, 100 * forward.error().max / size, learn::seconds_of(r));
  return line;
}

Material learn(const std::filesystem::path& scene,
    std::optional<std::filesystem::path> observations, std::optional<std::filesystem::path> clouds,
    std::optional<std::filesystem::path> output,
    std::optional<std::filesystem::path> checkpoint_arg, bool resume,
    std::optional<std::filesystem::path> report_dir, const py::handle& truth_material_arg,
    bool verbose, const py::kwargs& options) {
  if (!truth_material_arg.is_none() && !report_dir)
    throw InputError("truth_material", "is used by the report only: give report too");
  const LearnSettings settings = learn_settings(options);
  const io::TrainingSet set = io::read_learning_data(
      scene, observations.value_or(""), "observations", clouds.value_or(""), "clouds");
  // As the command: checkpoints after every iteration, by default beside the output.
  std::optional<std::filesystem::path> checkpoint = checkpoint_arg;
  if (!checkpoint && output)
    checkpoint = io::learning_checkpoint_path(*output, {});
  if (resume && !checkpoint)
    throw InputError("resume", "needs a checkpoint: give checkpoint or output");
  {
    // With resume the checkpoint is read and then rewritten on purpose: it is an output only.
    std::vector<CommandOutput> outputs;
    if (output)
      outputs.push_back({ *output, "learned material output" });
    if (checkpoint)
      outputs.push_back({ *checkpoint, "checkpoint" });
    std::vector<CommandInput> inputs = set.inputs;
    std::string path;
    if (is_path(truth_material_arg, path))
      inputs.push_back({ path, "true material (truth_material)" });
    if (report_dir) {
      for (CommandOutput& o : io::report_outputs(*report_dir, "report folder"))
        outputs.push_back(std::move(o));
      io::report_resource_dir(); // throws now, not after the work, if the report cannot be made
    }
    check_command_paths(inputs, outputs);
  }
  std::optional<Material> true_material;
  if (!truth_material_arg.is_none())
    true_material = material_argument(truth_material_arg);
  const io::LearningInputs inputs { scene.string(),
    observations ? observations->string() : (clouds ? clouds->string() : std::string()),
    io::recipe_options_to_json(settings.recipe) };
  std::optional<learn::RecipeResume> resumed;
  if (resume)
    resumed = io::resume_learning_checkpoint(*checkpoint, inputs, "resume");

  const double size = set.motions.front().scene.mesh.bounding_box_diagonal();
  const auto say = [verbose](const std::string& line) {
    if (verbose) {
      py::gil_scoped_acquire acquire;
      py::print(line, py::arg("flush") = true);
    }
  };
  if (resumed)
    say("resuming from " + checkpoint->string() + " at iteration "
        + std::to_string(resumed->loop.next_iteration));
  learn::RecipeCallbacks callbacks;
  callbacks.message = say;
  callbacks.loop.iteration = [&](const learn::IterationRecord& r) { say(iteration_line(r, size)); };
  bool interrupted = false;
  callbacks.loop.interrupted = [&interrupted] {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) {
      PyErr_Clear();
      interrupted = true;
    }
    return interrupted;
  };
  learn::ParameterFitReport fitted
      = resumed ? resumed->parameter_fit : learn::ParameterFitReport {};
  if (checkpoint) {
    callbacks.parameters_fitted = [&fitted](const learn::ParameterFitReport& f) { fitted = f; };
    callbacks.loop.checkpoint = [&](const learn::LearningState& s) {
      io::write_learning_checkpoint(*checkpoint, inputs, { fitted, s });
    };
  }
  io::MaterialFile learned;
  {
    py::gil_scoped_release release;
    const learn::RecipeResult result = learn::learn_material(
        set.motions, settings.recipe, callbacks, resumed ? &*resumed : nullptr);
    if (!result.interrupted) {
      learned = io::learned_material_file(set, scene.string(), result, settings.recipe);
      if (output)
        io::write_material_file(*output, learned);
      if (report_dir) {
        const io::LearningRunReportInputs report { scene.string(),
          output ? output->string() : std::string("learned"), set.motions, &result, &learned,
          true_material ? &true_material->model : nullptr,
          true_material ? true_material->source : std::string() };
        io::write_learning_run_report(*report_dir, report);
      }
    }
  }
  if (interrupted) {
    const std::string message = checkpoint
        ? "elastolearn.learn: interrupted; resume with the same call and resume=True (checkpoint "
            + checkpoint->string() + ")"
        : std::string("elastolearn.learn: interrupted");
    PyErr_SetString(PyExc_KeyboardInterrupt, message.c_str());
    throw py::error_already_set();
  }
  return make_material(std::move(learned), output ? output->string() : std::string("learned"));
}

py::object evaluate(const py::handle& scene_arg, const py::handle& material_arg,
    const py::handle& truth_arg, std::optional<std::filesystem::path> output,
    std::optional<std::filesystem::path> json, std::optional<std::string> solver,
    std::optional<std::filesystem::path> report_dir, const py::handle& truth_material_arg,
    bool progress) {
  if (!truth_material_arg.is_none() && !report_dir)
    throw InputError("truth_material", "is used by the report only: give report too");
  io::SceneFile file = scene_argument(scene_arg);
  {
    std::vector<CommandInput> inputs = file.inputs;
    for (const py::handle& h : { material_arg, truth_arg, truth_material_arg }) {
      std::string path;
      if (is_path(h, path))
        inputs.push_back({ path, "input" });
    }
    std::vector<CommandOutput> outputs;
    if (output)
      outputs.push_back({ *output, "learned trajectory output" });
    if (json)
      outputs.push_back({ *json, "JSON report (json)" });
    if (report_dir) {
      for (CommandOutput& o : io::report_outputs(*report_dir, "report folder"))
        outputs.push_back(std::move(o));
      io::report_resource_dir(); // throws now, not after the work, if the report cannot be made
    }
    check_command_paths(inputs, outputs);
  }
  if (solver)
    file.scene.linear_solver = sim::linear_solver_type_from_string(*solver);
  const Material material = material_argument(material_arg);
  std::string truth_source;
  const io::TrajectoryData truth_data = trajectory_argument(truth_arg, truth_source);
  const std::vector<VecX> truth = io::truth_frames(truth_data, truth_source, file.scene);
  std::optional<Material> true_material;
  if (!truth_material_arg.is_none())
    true_material = material_argument(truth_material_arg);
  io::EvaluationOptions options;
  if (output)
    options.learned_trajectory = *output;
  if (progress)
    options.progress = [](const std::string& label) { return terminal_progress(label); };
  const std::string scene_name = file.path.empty() ? std::string("scene") : file.path.string();
  nlohmann::json result;
  {
    py::gil_scoped_release release;
    const io::MaterialEvaluation e
        = io::evaluate_material(file.scene, material.file, material.source, truth, options);
    result = io::evaluation_to_json(e, file.scene, scene_name, material.source, truth_source);
    if (json)
      io::write_json_file(*json, result);
    if (report_dir) {
      const io::EvaluationReportInputs inputs { &file.scene, scene_name, &material.file,
        material.source, &truth, truth_source, true_material ? &true_material->model : nullptr };
      io::write_evaluation_report(*report_dir, inputs, e, options.progress);
    }
  }
  return to_python(result);
}

} // namespace

void bind_runs(py::module_& m) {
  py::class_<Simulation>(m, "Simulation",
      "What simulate returns: the trajectory and the run's report (completed, message, seconds, "
      "newton_iterations).")
      .def_readonly("trajectory", &Simulation::trajectory)
      .def_property_readonly(
          "positions",
          [](const Simulation& s) {
            return to_array(s.trajectory.positions, s.trajectory.rest_positions.rows());
          },
          "(T, n, 3) float64 [m]")
      .def_property_readonly(
          "velocities",
          [](const Simulation& s) {
            return to_array(s.trajectory.velocities, s.trajectory.rest_positions.rows());
          },
          "(T, n, 3) float64 [m/s]")
      .def_property_readonly(
          "time", [](const Simulation& s) { return to_array(s.trajectory.time); })
      .def_property_readonly("completed", [](const Simulation& s) { return s.report.completed; })
      .def_property_readonly("message", [](const Simulation& s) { return s.report.message; })
      .def_property_readonly("seconds", [](const Simulation& s) { return s.report.seconds; })
      .def_property_readonly(
          "newton_iterations", [](const Simulation& s) { return s.report.newton_iterations; })
      .def("__repr__", [](const Simulation& s) {
        return "<elastolearn.Simulation: " + std::to_string(s.trajectory.positions.size())
            + " frames, " + (s.report.completed ? "completed" : "stopped: " + s.report.message)
            + ">";
      });
  m.def("simulate", &simulate, py::arg("scene"), py::kw_only(), py::arg("frames") = py::none(),
      py::arg("material") = py::none(), py::arg("solver") = py::none(),
      py::arg("output") = py::none(), py::arg("every") = 1, py::arg("progress") = false);
  m.def("observe", &observe, py::arg("trajectory"), py::kw_only(),
      py::arg("visible_fraction") = py::none(), py::arg("vertices") = py::none(),
      py::arg("all_vertices") = false, py::arg("onto") = py::none(), py::arg("noise") = 0.0,
      py::arg("dropout") = 0.0, py::arg("dropout_burst") = 5.0, py::arg("seed") = 1,
      py::arg("output") = py::none());
  m.def("learn", &learn, py::arg("scene"), py::arg("observations") = py::none(), py::kw_only(),
      py::arg("clouds") = py::none(), py::arg("output") = py::none(),
      py::arg("checkpoint") = py::none(), py::arg("resume") = false, py::arg("report") = py::none(),
      py::arg("truth_material") = py::none(), py::arg("verbose") = false);
  m.def("learn_options", [] {
    std::vector<std::string> names;
    for (const auto& entry : learn_option_table())
      names.push_back(entry.first);
    return names;
  });
  m.def("evaluate", &evaluate, py::arg("scene"), py::arg("material"), py::arg("truth"),
      py::kw_only(), py::arg("output") = py::none(), py::arg("json") = py::none(),
      py::arg("solver") = py::none(), py::arg("report") = py::none(),
      py::arg("truth_material") = py::none(), py::arg("progress") = false);
}

} // namespace elastolearn::python
