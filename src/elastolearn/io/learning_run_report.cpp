#include <elastolearn/io/learning_run_report.hpp>
#include <elastolearn/io/report_builder.hpp>

#include <vector>

namespace elastolearn::io {

ReportOutcome write_learning_run_report(
    const std::filesystem::path& dir, const LearningRunReportInputs& in) {
  const learn::RecipeResult& result = *in.result;
  const MaterialFile& learned = *in.learned;
  LearningReport report;
  report.title = "elastolearn learn " + in.scene_path;
  const fem::MaterialModel written = material_model(learned, in.output_path);
  // The motions with the observations they were learned from (a cloud capture's are derived).
  std::vector<learn::Motion> motions(in.motions.begin(), in.motions.end());
  for (size_t i = 0; i < motions.size() && i < result.observed.size(); ++i)
    motions[i].observed = result.observed[i];
  add_recipe_sections(report, motions, result);
  const material::StretchRange* trained
      = learned.training_stretches ? &*learned.training_stretches : nullptr;
  if (written.correction || in.truth)
    add_correction_section(report, written, in.truth, trained);
  if (!in.truth)
    report.notes.push_back("No true material given (--truth-material): the correction is shown "
                           "without the truth's.");
  report.summary
      = { { "command", "learn" }, { "scene", in.scene_path }, { "learned", in.output_path },
          { "truth_material",
              in.truth_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(in.truth_path) },
          { "size_m", report.size }, { "recipe", learned.training.at("recipe") },
          { "best_iteration", result.loop.best_iteration }, { "seconds", result.seconds } };
  if (learned.training.contains("network"))
    report.summary["network"] = learned.training.at("network");
  report.provenance = learned.training;
  return write_learning_report(dir, report);
}

} // namespace elastolearn::io
