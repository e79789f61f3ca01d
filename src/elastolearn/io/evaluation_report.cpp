#include <elastolearn/io/evaluation_report.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/report_builder.hpp>
#include <elastolearn/learn/trajectory_error.hpp>

namespace elastolearn::io {

ReportOutcome write_evaluation_report(const std::filesystem::path& dir,
    const EvaluationReportInputs& in, const MaterialEvaluation& e,
    const std::function<ProgressCallback(const std::string& label)>& progress) {
  const MaterialFile& file = *in.material;
  const std::vector<VecX>& truth = *in.truth;
  const auto progress_of
      = [&](const std::string& label) { return progress ? progress(label) : ProgressCallback {}; };
  sim::Scene learned_scene = *in.scene;
  learned_scene.material = material_model(file, in.material_path);

  std::vector<ModelRun> extra;
  if (file.correction) {
    sim::Scene fitted = learned_scene;
    fitted.material.correction = nullptr;
    extra.push_back(
        { "fitted nominal", "the learned file's nominal without its correction", {}, {}, {}, {} });
    simulate_model(fitted, progress_of(extra.back().label), "", extra.back());
  }
  if (file.training.contains("teacher")) {
    sim::Scene teacher = learned_scene;
    teacher.material.correction = correction_from_json(
        JsonObject(file.training.at("teacher"), in.material_path, "training.teacher"));
    extra.push_back({ "learned RBF (the network's teacher)",
        describe_material_model(teacher.material), {}, {}, {}, {} });
    simulate_model(teacher, progress_of(extra.back().label), "", extra.back());
  }
  std::vector<LabelledRun> runs = { { "nominal", &e.nominal.frames, e.nominal.report.completed } };
  for (const ModelRun& r : extra)
    runs.push_back({ r.label, &r.frames, r.report.completed });
  const std::string learned_label
      = "learned" + (file.correction ? " (" + describe_correction(*file.correction) + ")" : "");
  runs.push_back({ learned_label, &e.learned.frames, e.learned.report.completed });

  LearningReport report;
  report.title = "elastolearn evaluate " + in.scene_path + " --material " + in.material_path;
  report.size = learned_scene.mesh.bounding_box_diagonal();
  add_test_motion_sections(
      report, "test motion " + in.scene_path, learned_scene, truth, runs, learned_label);
  const material::StretchRange* trained
      = file.training_stretches ? &*file.training_stretches : nullptr;
  if (file.correction || in.true_material)
    add_correction_section(report, learned_scene.material, in.true_material, trained);
  if (!in.true_material)
    report.notes.push_back("No true material given (--truth-material): the correction is shown "
                           "without the truth's.");
  nlohmann::json summary
      = evaluation_to_json(e, *in.scene, in.scene_path, in.material_path, in.truth_path);
  summary["command"] = "evaluate";
  summary["scene"] = in.scene_path;
  summary["material"] = in.material_path;
  summary["truth"] = in.truth_path;
  for (ModelRun& r : extra) {
    r.error = learn::position_error(r.frames, truth);
    r.percent = learn::as_percent_of(r.error, report.size);
    summary["others"][r.label] = model_run_to_json(r);
  }
  report.summary = summary;
  return write_learning_report(dir, report);
}

} // namespace elastolearn::io
