#include <elastolearn/core/error.hpp>
#include <elastolearn/io/report_builder.hpp>
#include <elastolearn/io/report_data.hpp>
#include <elastolearn/learn/error_distribution.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <algorithm>
#include <limits>

namespace elastolearn::io {

namespace {

const char* too_large = "No animation: two frames of the mesh's surface exceed the page's "
                        "budget (docs/report.md, \"The animation\").";

/// A model's run on the report's motion and its errors against the observations.
struct ObservedRun {
  std::string label;
  sim::ForwardRun run;
  Eigen::MatrixXd errors; ///< frames × observed vertices [m]
};

ObservedRun simulate_observed(
    const std::string& label, const learn::Motion& motion, const fem::MaterialModel& material) {
  sim::Scene scene = motion.scene;
  scene.material = material;
  ObservedRun out { label, sim::simulate_positions(scene), {} };
  if (!out.run.positions.empty())
    out.errors = learn::vertex_errors(out.run.positions, motion.observed);
  return out;
}

} // namespace

void add_recipe_sections(LearningReport& report, std::span<const learn::Motion> motions,
    const learn::RecipeResult& result, const std::vector<LabelledModel>& extra) {
  if (motions.empty())
    throw InputError("report", "no motion to report on");
  const learn::Motion& motion = motions.front();
  const fem::MaterialModel& given = motion.scene.material;
  report.size = motion.scene.mesh.bounding_box_diagonal();
  report.history = result.loop.history;
  report.data["convergence"] = convergence_json(result.loop.history);
  report.data["candidates"] = candidates_json(result);

  std::vector<ObservedRun> candidates;
  for (const learn::Candidate& c : result.candidates) {
    fem::MaterialModel m = c.kind == learn::CandidateKind::Nominal ? given : result.fitted_nominal;
    m.correction = c.correction;
    candidates.push_back(simulate_observed(candidate_label(c), motion, m));
  }
  std::vector<ObservedRun> extras;
  for (const LabelledModel& e : extra)
    extras.push_back(simulate_observed(e.label, motion, e.material));

  double low = std::numeric_limits<double>::infinity(), high = 0;
  for (const auto* runs : { &candidates, &extras }) {
    for (const ObservedRun& r : *runs) {
      for (double e : r.errors.reshaped()) {
        if (e > 0)
          low = std::min(low, e);
        high = std::max(high, e);
      }
    }
  }
  low = std::max(low, 1e-6 * report.size);
  if (high > low) {
    const std::vector<double> edges = learn::log_bin_edges(low, high, report_histogram_bins);
    std::vector<HistogramRow> rows;
    for (const ObservedRun& r : candidates) {
      const Eigen::VectorXd e = r.errors.reshaped();
      rows.push_back({ r.label,
          r.run.completed ? learn::histogram_counts(std::span(e.data(), e.size()), edges)
                          : std::vector<long> {},
          r.run.completed });
    }
    report.data["histograms"] = histograms_json("motion " + motion.name + ", at its "
            + std::to_string(motion.observed.num_observed()) + " observed vertices, every frame",
        edges, rows);
  }

  std::vector<ModelFrameErrors> models;
  const auto add_model = [&](const std::string& label, const ObservedRun& r) {
    models.push_back({ label, learn::frame_errors(r.errors), r.run.completed });
  };
  for (std::size_t i = 0; i < result.candidates.size(); ++i) {
    const auto kind = result.candidates[i].kind;
    if (kind == learn::CandidateKind::Nominal)
      add_model("nominal", candidates[i]);
    else if (kind == learn::CandidateKind::FittedNominal)
      add_model("fitted nominal (parameter fit)", candidates[i]);
  }
  if (result.chosen >= 0) {
    const auto& chosen = candidates[static_cast<std::size_t>(result.chosen)];
    add_model("learned (chosen: " + chosen.label + ")", chosen);
  }
  // The RBF and its distilled network both, whichever was chosen.
  for (std::size_t i = 0; i < result.candidates.size(); ++i) {
    const learn::Candidate& c = result.candidates[i];
    if (c.kind != learn::CandidateKind::Network || c.teacher < 0)
      continue;
    const auto teacher = static_cast<std::size_t>(c.teacher);
    if (static_cast<int>(teacher) != result.chosen)
      add_model("RBF (" + candidates[teacher].label + ")", candidates[teacher]);
    if (static_cast<int>(i) != result.chosen)
      add_model(candidates[i].label, candidates[i]);
  }
  for (const ObservedRun& r : extras)
    add_model(r.label, r);
  if (!report.data.contains("frame_errors"))
    report.data["frame_errors"] = nlohmann::json::array();
  report.data["frame_errors"].push_back(frame_errors_panel("training motion " + motion.name,
      "its observations (" + std::to_string(motion.observed.num_observed()) + " vertices)",
      motion.scene.dt, models));

  if (result.chosen >= 0) {
    const auto& chosen = candidates[static_cast<std::size_t>(result.chosen)];
    if (!chosen.run.positions.empty()) {
      report.animation = surface_animation(motion.scene.mesh, motion.scene.dt,
          { { "learned (" + chosen.label + ")", &chosen.run.positions } },
          &motion.observed.positions, "observed vertices");
      if (!report.animation)
        report.notes.push_back(too_large);
      report.animation_caption = "Motion " + motion.name
          + " simulated with the chosen material (surface) and the observed vertices (points).";
    }
  }
}

void add_test_motion_sections(LearningReport& report, const std::string& title,
    const sim::Scene& scene, const std::vector<VecX>& truth, const std::vector<LabelledRun>& runs,
    const std::string& animated) {
  std::vector<ModelFrameErrors> models;
  const LabelledRun* shown = nullptr;
  for (const LabelledRun& r : runs) {
    models.push_back(
        { r.label, learn::frame_errors(learn::vertex_errors(*r.frames, truth)), r.completed });
    if (r.label == animated)
      shown = &r;
  }
  if (!shown)
    throw InputError("report", "no run labelled " + animated + " to animate");
  if (report.size <= 0)
    report.size = scene.mesh.bounding_box_diagonal();
  if (!report.data.contains("frame_errors"))
    report.data["frame_errors"] = nlohmann::json::array();
  report.data["frame_errors"].push_back(
      frame_errors_panel(title, "the true trajectory (every vertex)", scene.dt, models));
  report.animation = surface_animation(
      scene.mesh, scene.dt, { { "truth", &truth }, { shown->label, shown->frames } });
  if (!report.animation)
    report.notes.push_back(too_large);
  report.animation_caption = title + ": the true motion (grey) and the " + shown->label
      + " one side by side; \"overlay\" draws the truth as a wireframe over it.";
}

void add_correction_section(LearningReport& report, const fem::MaterialModel& learned,
    const fem::MaterialModel* truth, const material::StretchRange* training) {
  report.data["correction"] = correction_curves_json(learned, truth, training);
}

} // namespace elastolearn::io
