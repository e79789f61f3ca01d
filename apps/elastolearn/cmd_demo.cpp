// elastolearn demo: the end-to-end learning run of examples/04_learning, in one command.
// A bar's ground truth (neo-Hookean) is simulated and 13 % of its surface vertices observed; a
// correction of a wrong nominal (corotated, 1.75× too stiff) is learned from them; nominal and
// learned models are then compared with the truth on a different, larger test motion (err_L).
#include "command.hpp"
#include "demo_scenes.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/io/learned_material.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/nominal_parameters.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/report_builder.hpp>
#include <elastolearn/io/report_resources.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/scene_output.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <cstdio>
#include <nlohmann/json.hpp>

namespace {

using namespace elastolearn;
namespace fs = std::filesystem;

/// Simulate and write HDF5 + ParaView; returns the frames (flat) read back from the file.
std::vector<VecX> simulate_and_save(
    const sim::Scene& scene, const fs::path& out, const std::string& name) {
  fs::path pvd;
  const auto report = io::simulate_to_files(
      scene, { out / (name + ".h5"), out / (name + "_vtu"), 1 }, terminal_progress(name), &pvd);
  if (!report.completed)
    throw InputError(name, report.message);
  std::printf("   %-13s %s  (%s)\n", name.c_str(), (out / (name + ".h5")).c_str(), pvd.c_str());
  std::vector<VecX> frames;
  for (const auto& p : io::read_trajectory_h5(out / (name + ".h5")).positions)
    frames.emplace_back(flatten(p));
  return frames;
}

void run_demo(const fs::path& out, double fraction) {
  const auto start = Clock::now();
  // The demo reads no file (its scenes are built in): only its folder is checked.
  std::vector<CommandOutput> outputs = io::report_outputs(out / "report", "demo report folder");
  outputs.insert(outputs.begin(), { out, "demo output folder (-o)", OutputKind::folder });
  check_command_paths({}, outputs);
  io::report_resource_dir(); // throws now, not after the work, if the report cannot be made
  fs::create_directories(out);
  const auto train
      = io::parse_scene(nlohmann::json::parse(app::kDemoTrainScene), "built-in bar_train.json", out)
            .scene;
  const auto test
      = io::parse_scene(nlohmann::json::parse(app::kDemoTestScene), "built-in bar_test.json", out)
            .scene;
  const auto truth_file = io::parse_material_file(
      nlohmann::json::parse(app::kDemoTruthMaterial), "built-in truth.json");
  const fem::MaterialModel truth = io::material_model(truth_file, "built-in truth.json");
  auto with_material = [](sim::Scene s, const fem::MaterialModel& m) {
    s.material = m;
    return s;
  };
  std::printf(
      "elastolearn demo: learn a bar's material from %g %% of its surface (%d tets, %d frames)\n",
      100 * fraction, train.mesh.num_tets(), train.frames);
  std::printf("   truth:   %s\n   nominal: %s\n", io::describe_material_model(truth).c_str(),
      io::describe_material_model(train.material).c_str());

  std::printf("1. ground-truth training motion (droop under gravity)\n");
  const auto truth_frames = simulate_and_save(with_material(train, truth), out, "train_truth");
  std::vector<Positions> frames;
  for (const auto& x : truth_frames)
    frames.emplace_back(unflatten(x));
  const auto ids = observe::select_visible_vertices(train.mesh, fraction, 1);
  const auto observed = observe::observe_vertices(frames, train.dt, ids, 0.0, 1);
  io::write_observation_h5(out / "observations.h5", observed);
  std::printf("2. observed %d of %zu surface vertices: %s\n", observed.num_observed(),
      train.mesh.surface_vertices().size(), (out / "observations.h5").c_str());

  std::printf(
      "3. learning with the one recipe (errors at the observed vertices, %% of the size)\n");
  const double size = train.mesh.bounding_box_diagonal();
  learn::RecipeCallbacks callbacks;
  callbacks.message = [](const std::string& line) {
    std::printf("   %s\n", line.c_str());
    std::fflush(stdout);
  };
  callbacks.loop.progress = terminal_progress("learn");
  callbacks.loop.iteration = [&](const learn::IterationRecord& r) {
    const learn::ForwardOutcome& forward = learn::forward_of(r);
    if (!forward.completed()) {
      std::printf("   iteration %d: %s\n", learn::iteration_of(r), forward.message().c_str());
      return;
    }
    std::printf("   iteration %d: rms %.4f %%, max %.4f %%", learn::iteration_of(r),
        100 * forward.error().rms / size, 100 * forward.error().max / size);
    if (const auto* step = learn::forward_fit_of(r))
      std::printf("  (forward-fit step %s, %.1f s)\n", step->accepted ? "accepted" : "rejected",
          learn::seconds_of(r));
    else if (const auto* stages = learn::stages_of(r))
      std::printf(
          ", control force %.3e N, %.1f s\n", stages->control_force_rms, learn::seconds_of(r));
    else if (std::get<learn::LoopRecord>(r).damped_update())
      std::printf("  (no better than the best: trying half its step)\n");
    else
      std::printf("  (last forward check)\n");
    std::fflush(stdout);
  };
  const std::vector<learn::Motion> motions { { "the droop", train, observed } };
  const learn::RecipeResult result = learn::learn_material(motions, {}, callbacks);
  const learn::Candidate& chosen = result.choice();
  const nlohmann::json nominal_json = nlohmann::json::parse(app::kDemoTrainScene).at("material");
  sim::Scene fitted = train;
  fitted.material = result.fitted_nominal;
  io::MaterialFile learned { chosen.kind == learn::CandidateKind::Nominal
        ? nominal_json
        : io::with_nominal_parameters(nominal_json, result.parameter_fit.fitted, true),
    chosen.correction, { { "demo", true }, { "chosen", learn::to_string(chosen.kind) } },
    learn::training_stretch_range(fitted, chosen.correction) };
  io::add_network_provenance(learned.training, result);
  io::write_material_file(out / "learned.json", learned);
  std::printf("   chose %s by its error on %s; learned material: %s\n",
      learn::to_string(chosen.kind).c_str(), result.validation_data.c_str(),
      (out / "learned.json").c_str());

  std::printf("4. a different test motion (thrown upward): truth, nominal, fitted, learned\n");
  const auto test_truth = simulate_and_save(with_material(test, truth), out, "test_truth");
  const auto test_nominal = simulate_and_save(test, out, "test_nominal");
  const auto test_fitted
      = simulate_and_save(with_material(test, result.fitted_nominal), out, "test_fitted");
  const auto test_learned = simulate_and_save(
      with_material(test, result.material(train.material)), out, "test_learned");
  const auto e_nominal
      = learn::as_percent_of(learn::position_error(test_nominal, test_truth), size);
  const auto e_fitted = learn::as_percent_of(learn::position_error(test_fitted, test_truth), size);
  const auto e_learned
      = learn::as_percent_of(learn::position_error(test_learned, test_truth), size);
  // With a network chosen, its RBF teacher beside it.
  std::vector<VecX> test_teacher;
  bool teacher_completed = false;
  if (chosen.kind == learn::CandidateKind::Network) {
    sim::Scene s = with_material(test, result.fitted_nominal);
    s.material.correction = result.candidates.at(static_cast<size_t>(chosen.teacher)).correction;
    sim::ForwardRun run = sim::simulate_positions(s);
    teacher_completed = run.completed;
    test_teacher = std::move(run.positions);
  }
  std::printf("\n   %-16s %10s %10s\n", "model", "err_L [%]", "mean [%]");
  std::printf("   %-16s %10.3f %10.4f\n   %-16s %10.3f %10.4f\n   %-16s %10.4f %10.5f\n", "nominal",
      e_nominal.max, e_nominal.mean, "fitted nominal", e_fitted.max, e_fitted.mean, "learned",
      e_learned.max, e_learned.mean);
  if (teacher_completed) {
    const auto e = learn::as_percent_of(learn::position_error(test_teacher, test_truth), size);
    std::printf("   %-16s %10.4f %10.5f   (the network's RBF teacher)\n", "RBF", e.max, e.mean);
  }
  if (learned.training_stretches) {
    learn::StretchCoverage coverage(test.mesh, learned.training_stretches);
    for (const auto& x : test_learned)
      coverage.add_frame(x);
    std::fputs(learn::coverage_report(coverage, "   ").c_str(), stdout);
  }
  std::printf("   err_L %.0fx lower than the nominal's and %.1fx lower than the fitted nominal's\n",
      e_nominal.max / e_learned.max, e_fitted.max / e_learned.max);

  std::printf("5. report (plots, animation of the true and learned test motions)\n");
  std::fflush(stdout);
  const auto report_start = Clock::now();
  io::LearningReport report;
  report.title = "elastolearn demo: a bar's material learned from "
      + std::to_string(observed.num_observed()) + " observed vertices";
  io::add_recipe_sections(report, motions, result);
  std::vector<io::LabelledRun> test_runs { { "nominal", &test_nominal },
    { "fitted nominal (parameter fit)", &test_fitted },
    { "learned (" + learn::to_string(chosen.kind) + ")", &test_learned } };
  if (!test_teacher.empty())
    test_runs.push_back({ "the network's RBF teacher", &test_teacher, teacher_completed });
  io::add_test_motion_sections(
      report, "test motion (thrown upward)", test, test_truth, test_runs, test_runs[2].label);
  const fem::MaterialModel learned_model = result.material(train.material);
  io::add_correction_section(report, learned_model, &truth,
      learned.training_stretches ? &*learned.training_stretches : nullptr);
  auto percent_json = [](const learn::ErrorSummary& e) {
    return nlohmann::json { { "err_L_percent", e.max }, { "mean_percent", e.mean },
      { "rms_percent", e.rms } };
  };
  report.summary = { { "command", "demo" }, { "truth", io::describe_material_model(truth) },
    { "nominal", io::describe_material_model(train.material) },
    { "observed_vertices", observed.num_observed() }, { "size_m", size },
    { "chosen", learn::to_string(chosen.kind) },
    { "test_motion",
        { { "nominal", percent_json(e_nominal) }, { "fitted_nominal", percent_json(e_fitted) },
            { "learned", percent_json(e_learned) } } },
    { "learning_seconds", result.seconds } };
  const io::ReportOutcome outcome = io::write_learning_report(out / "report", report);
  std::printf("   %s, %.1f s\n", io::describe_report(out / "report", outcome).c_str(),
      seconds_since(report_start));
  std::printf("   demo took %.0f s\n", seconds_since(start));
}

void add_demo_command(CLI::App& root) {
  auto dir = std::make_shared<std::string>("elastolearn-demo");
  auto fraction = std::make_shared<double>(0.13);
  auto* cmd = root.add_subcommand(
      "demo", "Learn a material end to end on a built-in example and evaluate it");
  cmd->add_option("-o,--output-dir", *dir, "where to write the results")->capture_default_str();
  cmd->add_option("--visible-fraction", *fraction, "fraction of surface vertices observed")
      ->capture_default_str();
  cmd->callback([dir, fraction] { run_demo(*dir, *fraction); });
}

} // namespace

ELASTOLEARN_COMMAND(1, add_demo_command)
