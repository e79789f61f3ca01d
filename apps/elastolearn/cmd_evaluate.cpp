// elastolearn evaluate test_scene.json --material learned.json --truth test_traj.h5
//                     [--json report.json] [-o learned_traj.h5]
// Paper 000 Table 1's err_L: simulate the test scene with its own (nominal) material and with the
// learned material, and compare both with the true trajectory over all vertices, or with an
// observation file's vertices (e.g. `observe --onto`: a fine motion seen at a coarse mesh's
// vertices).
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/evaluation_report.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_evaluation.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/report_resources.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>

#include <cstdio>

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

/// The progress display of a run labelled `label` (none with --quiet).
ProgressCallback progress(const EvaluateOptions& opts, const std::string& label) {
  return opts.quiet ? ProgressCallback {} : terminal_progress(label);
}

void run_evaluate(const EvaluateOptions& opts) {
  if (!opts.truth_material.empty() && opts.report.empty())
    throw InputError("--truth-material", "is used by the report only: give --report DIR too");
  io::SceneFile file = io::read_scene_file(opts.scene);
  {
    std::vector<CommandInput> inputs = file.inputs;
    inputs.push_back({ opts.material, "material (--material)" });
    inputs.push_back({ opts.truth, "truth (--truth)" });
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
  const sim::Scene& scene = file.scene;
  const io::MaterialFile material_file = io::read_material_file(opts.material);
  const io::EvaluationTruth truth = io::read_evaluation_truth(opts.truth, scene);
  if (truth.observed && !opts.report.empty())
    throw InputError("--report",
        "needs a trajectory of every vertex as --truth (" + opts.truth
            + " is an observation file): the report animates the true motion");
  std::optional<fem::MaterialModel> true_material;
  if (!opts.truth_material.empty()) {
    true_material
        = io::material_model(io::read_material_file(opts.truth_material), opts.truth_material);
  }

  io::EvaluationOptions options;
  options.learned_trajectory = opts.output;
  if (!opts.quiet)
    options.progress = [](const std::string& label) { return terminal_progress(label); };
  options.started = [&](const io::MaterialEvaluation& e) {
    std::printf("scene %s: %d vertices, %d tets, %d frames of dt = %g s, size (rest bounding-box "
                "diagonal) %g m\n",
        scene.name.c_str(), scene.mesh.num_vertices(), scene.mesh.num_tets(), scene.frames,
        scene.dt, e.size);
    std::printf("truth:   %s (%d frames%s)\nnominal: %s\nlearned: %s\n", opts.truth.c_str(),
        truth.num_frames(),
        truth.observed
            ? (", observations of " + std::to_string(truth.observed->num_observed()) + " vertices")
                  .c_str()
            : "",
        e.nominal.description.c_str(), e.learned.description.c_str());
    std::fflush(stdout);
  };
  const io::MaterialEvaluation e
      = io::evaluate_material(scene, material_file, opts.material, truth, options);

  std::printf("\n%-9s %12s %12s %12s %12s %11s\n", "model", "err_L [%]", "mean [%]", "rms [%]",
      "max [m]", "worst frame");
  for (const io::ModelRun* run : { &e.nominal, &e.learned }) {
    std::printf("%-9s %12.4g %12.4g %12.4g %12.4g %11d%s\n", run->label.c_str(), run->percent.max,
        run->percent.mean, run->percent.rms, run->error.max, run->error.worst_frame,
        run->report.completed ? "" : "  (stopped early)");
  }
  const auto max_ratio = e.max_ratio();
  const auto mean_ratio = e.mean_ratio();
  if (!e.completed())
    std::printf("improvement: not measured (a simulation stopped early; see below)\n");
  else if (max_ratio && mean_ratio)
    std::printf(
        "improvement: err_L %.3gx lower, mean error %.3gx lower\n", *max_ratio, *mean_ratio);
  else
    std::printf("improvement: the learned material reproduces the truth exactly\n");
  if (!opts.output.empty() && !e.learned.frames.empty())
    std::printf("learned trajectory: %s\n", opts.output.c_str());
  // Where the test motion leaves the correction's training range (files that record it).
  if (e.coverage)
    std::fputs(learn::coverage_report(*e.coverage).c_str(), stdout);

  if (!opts.json.empty()) {
    io::write_json_file(
        opts.json, io::evaluation_to_json(e, scene, opts.scene, opts.material, opts.truth));
    std::printf("report: %s\n", opts.json.c_str());
  }
  if (!opts.report.empty()) {
    const io::EvaluationReportInputs inputs { &scene, opts.scene, &material_file, opts.material,
      &truth.frames, opts.truth, true_material ? &*true_material : nullptr };
    const io::ReportOutcome written = io::write_evaluation_report(opts.report, inputs, e,
        [&opts](const std::string& label) { return progress(opts, label); });
    std::printf("%s\n", io::describe_report(opts.report, written).c_str());
  }
  for (const io::ModelRun* run : { &e.nominal, &e.learned }) {
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
  cmd->add_option("--truth", opts->truth,
         "true trajectory of the test scene (HDF5, e.g. from simulate), or an observation file of "
         "its vertices (e.g. from observe --onto: err_L over the observed vertices)")
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
