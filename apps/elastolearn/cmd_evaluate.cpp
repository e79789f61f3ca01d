// elastolearn evaluate test_scene.json --material learned.json --truth test_traj.h5
//                     [--json report.json] [-o learned_traj.h5]
// Paper 000 Table 1's err_L: simulate the test scene with its own (nominal) material and with the
// learned material, and compare both with the true trajectory over all vertices.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/report_builder.hpp>
#include <elastolearn/io/report_resources.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <cmath>
#include <cstdio>
#include <optional>

namespace {

using namespace elastolearn;

struct EvaluateOptions {
  std::string scene;
  std::string material;
  std::string truth;
  std::string json;
  std::string output;
  std::string solver;
  std::string report;
  std::string truth_material;
  bool quiet = false;
};

/// One simulated model and its error against the truth.
struct ModelRun {
  std::string label;
  std::string description;
  std::vector<VecX> frames; ///< flat 3n, frame 0 = initial state
  sim::SimulationReport report;
  learn::ErrorSummary error; ///< [m]
  learn::ErrorSummary percent; ///< [% of the rest bounding-box diagonal]
};

/// The truth as flat frames, after checking that it belongs to `scene` (same vertex count and
/// rest shape, scene.frames + 1 frames spaced scene.dt). Throws InputError naming the file.
std::vector<VecX> read_truth(const std::string& path, const sim::Scene& scene) {
  const io::TrajectoryData truth = io::read_trajectory_h5(path);
  const int n = scene.mesh.num_vertices();
  if (truth.rest_positions.rows() != n) {
    throw InputError(path + ": /rest_positions",
        "has " + std::to_string(truth.rest_positions.rows()) + " vertices but the scene's mesh has "
            + std::to_string(n) + " (a trajectory of a different mesh?)");
  }
  const double tolerance = 1e-9 * scene.mesh.bounding_box_diagonal();
  const double offset
      = (truth.rest_positions - scene.mesh.rest_positions()).rowwise().norm().maxCoeff();
  if (!(offset <= tolerance)) {
    throw InputError(path + ": /rest_positions",
        "differ from the scene's mesh by up to " + std::to_string(offset)
            + " m (a trajectory of a different mesh?)");
  }
  const int expected = scene.frames + 1;
  if (int(truth.positions.size()) != expected) {
    throw InputError(path + ": /positions",
        "has " + std::to_string(truth.positions.size()) + " frames but the scene simulates "
            + std::to_string(expected) + " (" + std::to_string(scene.frames)
            + " steps + the initial state)");
  }
  const double dt = observe::uniform_time_step(truth.time, path + ": /time");
  if (std::abs(dt - scene.dt) > 1e-6 * scene.dt) {
    throw InputError(path + ": /time",
        "frames are " + std::to_string(dt) + " s apart but the scene's time step is "
            + std::to_string(scene.dt) + " s");
  }
  std::vector<VecX> frames;
  frames.reserve(truth.positions.size());
  for (const Positions& p : truth.positions)
    frames.emplace_back(flatten(p));
  return frames;
}

/// Simulate `scene`, keeping every frame in memory and, if `output` is given, writing them.
void simulate(const sim::Scene& scene, bool quiet, const std::string& output, ModelRun& run) {
  std::optional<io::TrajectoryWriter> writer;
  if (!output.empty())
    writer.emplace(output, scene.mesh.rest_positions(), scene.mesh.tets(), Edges(),
        scene.mesh.surface_faces());
  auto sink = [&](int, double time, const VecX& x, const VecX& v) {
    run.frames.push_back(x);
    if (writer)
      writer->append(time, unflatten(x), unflatten(v));
  };
  run.report = sim::run_simulation(
      scene, sink, quiet ? ProgressCallback {} : terminal_progress(run.label));
  if (writer && writer->frames() > 0) {
    const std::map<std::string, std::string> metadata = { { "scene", scene.name },
      { "material", run.description }, { "dt", std::to_string(scene.dt) },
      { "status", run.report.completed ? "completed" : "stopped: " + run.report.message } };
    writer->finish(metadata);
  }
}

nlohmann::json run_to_json(const ModelRun& run) {
  const auto& e = run.error;
  const auto& p = run.percent;
  return { { "material", run.description }, { "err_L_percent", p.max }, { "mean_percent", p.mean },
    { "rms_percent", p.rms }, { "max_error", e.max }, { "mean_error", e.mean },
    { "rms_error", e.rms }, { "worst_frame", e.worst_frame }, { "worst_vertex", e.worst_vertex },
    { "frames_compared", run.frames.size() }, { "completed", run.report.completed },
    { "message", run.report.message }, { "seconds", run.report.seconds } };
}

/// nominal / learned, or null (JSON) / "exact" (text) when the learned error is zero.
std::optional<double> ratio(double nominal, double learned) {
  if (!(learned > 0))
    return std::nullopt;
  return nominal / learned;
}

/// The comparison's numbers: each model's errors and the improvement.
nlohmann::json report_json(const ModelRun& nominal, const ModelRun& learned, double size) {
  const auto max_ratio = ratio(nominal.error.max, learned.error.max);
  const auto mean_ratio = ratio(nominal.error.mean, learned.error.mean);
  return { { "size", size }, { "nominal", run_to_json(nominal) },
    { "learned", run_to_json(learned) },
    { "improvement",
        { { "err_L", max_ratio ? nlohmann::json(*max_ratio) : nlohmann::json(nullptr) },
            { "mean", mean_ratio ? nlohmann::json(*mean_ratio) : nlohmann::json(nullptr) } } } };
}

/// The --report folder: error per frame of the nominal, the fitted-parameter baseline (the
/// learned file's nominal without its correction), the learned material and, for a network, its
/// RBF teacher; the animation of the true and learned motions; the learned correction's curves.
void write_report(const EvaluateOptions& opts, const io::MaterialFile& file,
    const sim::Scene& learned_scene, const std::vector<VecX>& truth, const ModelRun& nominal,
    const ModelRun& learned, const fem::MaterialModel* true_material, nlohmann::json summary) {
  std::vector<ModelRun> extra;
  if (file.correction) {
    sim::Scene fitted = learned_scene;
    fitted.material.correction = nullptr;
    extra.push_back(
        { "fitted nominal", "the learned file's nominal without its correction", {}, {}, {}, {} });
    simulate(fitted, opts.quiet, "", extra.back());
  }
  if (file.training.contains("teacher")) {
    sim::Scene teacher = learned_scene;
    teacher.material.correction = io::correction_from_json(
        io::JsonObject(file.training.at("teacher"), opts.material, "training.teacher"));
    extra.push_back({ "learned RBF (the network's teacher)",
        io::describe_material_model(teacher.material), {}, {}, {}, {} });
    simulate(teacher, opts.quiet, "", extra.back());
  }
  std::vector<io::LabelledRun> runs = { { "nominal", &nominal.frames, nominal.report.completed } };
  for (const ModelRun& r : extra)
    runs.push_back({ r.label, &r.frames, r.report.completed });
  const std::string learned_label
      = "learned" + (file.correction ? " (" + io::describe_correction(*file.correction) + ")" : "");
  runs.push_back({ learned_label, &learned.frames, learned.report.completed });

  io::LearningReport report;
  report.title = "elastolearn evaluate " + opts.scene + " --material " + opts.material;
  report.size = learned_scene.mesh.bounding_box_diagonal();
  io::add_test_motion_sections(
      report, "test motion " + opts.scene, learned_scene, truth, runs, learned_label);
  const material::StretchRange* trained
      = file.training_stretches ? &*file.training_stretches : nullptr;
  if (file.correction || true_material)
    io::add_correction_section(report, learned_scene.material, true_material, trained);
  if (!true_material)
    report.notes.push_back("No true material given (--truth-material): the correction is shown "
                           "without the truth's.");
  summary["command"] = "evaluate";
  summary["scene"] = opts.scene;
  summary["material"] = opts.material;
  summary["truth"] = opts.truth;
  for (ModelRun& r : extra) {
    r.error = learn::position_error(r.frames, truth);
    r.percent = learn::as_percent_of(r.error, report.size);
    summary["others"][r.label] = run_to_json(r);
  }
  report.summary = summary;
  std::printf("%s\n",
      io::describe_report(opts.report, io::write_learning_report(opts.report, report)).c_str());
}

void run_evaluate(const EvaluateOptions& opts) {
  if (!opts.truth_material.empty() && opts.report.empty())
    throw InputError("--truth-material", "is used by the report only: give --report DIR too");
  io::SceneFile file = io::read_scene_file(opts.scene);
  {
    std::vector<CommandInput> inputs = file.inputs;
    inputs.push_back({ opts.material, "material (--material)" });
    inputs.push_back({ opts.truth, "true trajectory (--truth)" });
    std::vector<CommandOutput> outputs;
    if (!opts.output.empty())
      outputs.push_back({ opts.output, "learned trajectory output (-o)" });
    if (!opts.json.empty())
      outputs.push_back({ opts.json, "JSON report (--json)" });
    if (!opts.truth_material.empty())
      inputs.push_back({ opts.truth_material, "true material (--truth-material)" });
    if (!opts.report.empty()) {
      for (CommandOutput& output : io::report_outputs(opts.report, "--report folder"))
        outputs.push_back(std::move(output));
      io::report_resource_dir(); // throws now, not after the work, if the report cannot be made
    }
    check_command_paths(inputs, outputs);
  }
  if (!opts.solver.empty())
    file.scene.linear_solver = sim::linear_solver_type_from_string(opts.solver);
  const sim::Scene& nominal_scene = file.scene;
  sim::Scene learned_scene = file.scene;
  const io::MaterialFile material_file = io::read_material_file(opts.material);
  learned_scene.material = io::material_model(material_file, opts.material);
  const std::vector<VecX> truth = read_truth(opts.truth, nominal_scene);
  std::optional<fem::MaterialModel> true_material;
  if (!opts.truth_material.empty()) {
    true_material
        = io::material_model(io::read_material_file(opts.truth_material), opts.truth_material);
  }
  const double size = nominal_scene.mesh.bounding_box_diagonal();

  std::printf("scene %s: %d vertices, %d tets, %d frames of dt = %g s, size (rest bounding-box "
              "diagonal) %g m\n",
      nominal_scene.name.c_str(), nominal_scene.mesh.num_vertices(), nominal_scene.mesh.num_tets(),
      nominal_scene.frames, nominal_scene.dt, size);
  ModelRun nominal { "nominal",
    io::describe_material_model(nominal_scene.material) + " (the scene's)", {}, {}, {}, {} };
  ModelRun learned { "learned",
    io::describe_material_model(learned_scene.material) + " (" + opts.material + ")", {}, {}, {},
    {} };
  std::printf("truth:   %s (%zu frames)\nnominal: %s\nlearned: %s\n", opts.truth.c_str(),
      truth.size(), nominal.description.c_str(), learned.description.c_str());
  std::fflush(stdout);

  simulate(nominal_scene, opts.quiet, "", nominal);
  simulate(learned_scene, opts.quiet, opts.output, learned);
  for (ModelRun* run : { &nominal, &learned }) {
    run->error = learn::position_error(run->frames, truth);
    run->percent = learn::as_percent_of(run->error, size);
  }

  std::printf("\n%-9s %12s %12s %12s %12s %11s\n", "model", "err_L [%]", "mean [%]", "rms [%]",
      "max [m]", "worst frame");
  for (const ModelRun* run : { &nominal, &learned }) {
    std::printf("%-9s %12.4g %12.4g %12.4g %12.4g %11d%s\n", run->label.c_str(), run->percent.max,
        run->percent.mean, run->percent.rms, run->error.max, run->error.worst_frame,
        run->report.completed ? "" : "  (stopped early)");
  }
  const auto max_ratio = ratio(nominal.error.max, learned.error.max);
  const auto mean_ratio = ratio(nominal.error.mean, learned.error.mean);
  if (!nominal.report.completed || !learned.report.completed)
    std::printf("improvement: not measured (a simulation stopped early; see below)\n");
  else if (max_ratio && mean_ratio)
    std::printf(
        "improvement: err_L %.3gx lower, mean error %.3gx lower\n", *max_ratio, *mean_ratio);
  else
    std::printf("improvement: the learned material reproduces the truth exactly\n");
  if (!opts.output.empty() && !learned.frames.empty())
    std::printf("learned trajectory: %s\n", opts.output.c_str());
  // Where the test motion leaves the correction's training range (files that record it).
  std::optional<learn::StretchCoverage> coverage;
  if (material_file.training_stretches && material_file.correction) {
    coverage.emplace(nominal_scene.mesh, material_file.training_stretches);
    for (const VecX& x : learned.frames)
      coverage->add_frame(x);
    std::fputs(learn::coverage_report(*coverage).c_str(), stdout);
  }

  if (!opts.json.empty()) {
    nlohmann::json report = { { "format", "elastolearn-evaluation/1" }, { "scene", opts.scene },
      { "material", opts.material }, { "truth", opts.truth },
      { "vertices", nominal_scene.mesh.num_vertices() }, { "tets", nominal_scene.mesh.num_tets() },
      { "frames", truth.size() }, { "dt", nominal_scene.dt }, { "size", size } };
    report.update(report_json(nominal, learned, size));
    if (coverage) {
      report["stretches"] = { { "visited", io::stretch_range_to_json(coverage->visited()) },
        { "trained", io::stretch_range_to_json(*coverage->trained()) },
        { "fraction_outside", coverage->fraction_outside() } };
    }
    io::write_json_file(opts.json, report);
    std::printf("report: %s\n", opts.json.c_str());
  }
  if (!opts.report.empty()) {
    write_report(opts, material_file, learned_scene, truth, nominal, learned,
        true_material ? &*true_material : nullptr, report_json(nominal, learned, size));
  }
  for (const ModelRun* run : { &nominal, &learned }) {
    if (!run->report.completed) {
      std::fprintf(stderr,
          "elastolearn: error: the %s simulation %s (errors above cover frames 0..%zu)\n",
          run->label.c_str(), run->report.message.c_str(), run->frames.size() - 1);
      throw CLI::RuntimeError(1);
    }
  }
}

void add_evaluate_command(CLI::App& root) {
  auto opts = std::make_shared<EvaluateOptions>();
  auto* cmd = root.add_subcommand("evaluate",
      "Compare the nominal and a learned material with a true trajectory (err_L, paper 000 Table "
      "1)");
  cmd->add_option(
         "scene", opts->scene, "test scene (elastolearn-scene/1 JSON); its material is the nominal")
      ->required();
  cmd->add_option(
         "--material", opts->material, "learned material file (elastolearn-material/1 JSON)")
      ->required();
  cmd->add_option(
         "--truth", opts->truth, "true trajectory of the test scene (HDF5, e.g. from simulate)")
      ->required();
  cmd->add_option("--json", opts->json, "also write the numbers to this JSON file");
  cmd->add_option("-o,--output", opts->output, "write the learned material's trajectory (HDF5)");
  cmd->add_option(
      "--solver", opts->solver, "linear solver: cholmod | cg | eigen-ldlt (overrides the scene)");
  cmd->add_option("--report", opts->report,
      "folder for a report: report.html with the error per frame, the learned correction and an "
      "animation of the true and learned motions (docs/report.md)");
  cmd->add_option("--truth-material", opts->truth_material,
      "the true material (elastolearn-material/1 JSON), when known: the report plots the learned "
      "correction and damping against it");
  cmd->add_flag("-q,--quiet", opts->quiet, "no progress line");
  cmd->callback([opts] { run_evaluate(*opts); });
}

} // namespace

ELASTOLEARN_COMMAND(45, add_evaluate_command)
