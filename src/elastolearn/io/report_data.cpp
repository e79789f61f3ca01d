#include <elastolearn/io/report_data.hpp>
#include <elastolearn/learn/correction_curves.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::io {

namespace {

nlohmann::json measured(bool valid, double value) {
  return valid && std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

/// The stress along the stretched axis and across it on a uniaxial path: sorted (s, 1, 1) puts
/// s first when s ≥ 1 and last when s < 1.
void split_uniaxial(const learn::StretchPath& path, const std::vector<Vec3>& stress,
    std::vector<double>& axial, std::vector<double>& lateral) {
  for (std::size_t i = 0; i < stress.size(); ++i) {
    const bool tension = path.x[i] >= 1;
    axial.push_back(stress[i][tension ? 0 : 2]);
    lateral.push_back(stress[i][tension ? 1 : 0]);
  }
}

std::vector<double> norms(const std::vector<Vec3>& v) {
  std::vector<double> out;
  out.reserve(v.size());
  for (const Vec3& x : v)
    out.push_back(x.norm());
  return out;
}

} // namespace

nlohmann::json convergence_json(const std::vector<learn::IterationRecord>& history) {
  nlohmann::json iteration = nlohmann::json::array(), forward_fit = nlohmann::json::array(),
                 completed = nlohmann::json::array(), rms = nlohmann::json::array(),
                 max = nlohmann::json::array(), control = nlohmann::json::array();
  for (const auto& r : history) {
    const learn::ForwardOutcome& forward = learn::forward_of(r);
    const learn::SpaceTimeStages* stages = learn::stages_of(r);
    iteration.push_back(learn::iteration_of(r));
    forward_fit.push_back(learn::forward_fit_of(r) != nullptr);
    completed.push_back(forward.completed());
    rms.push_back(forward.completed() ? measured(true, forward.error().rms) : nullptr);
    max.push_back(forward.completed() ? measured(true, forward.error().max) : nullptr);
    // The control forces come from the trajectory stages, which a forward-fit step, a damped
    // update and the last forward check do not run.
    control.push_back(stages ? measured(true, stages->control_force_rms) : nullptr);
  }
  return { { "iteration", iteration }, { "forward_fit", forward_fit }, { "completed", completed },
    { "forward_rms_m", rms }, { "forward_max_m", max }, { "control_force_rms_N", control } };
}

std::string candidate_label(const learn::Candidate& c) {
  switch (c.kind) {
  case learn::CandidateKind::Nominal:
    return "nominal";
  case learn::CandidateKind::FittedNominal:
    return "fitted nominal";
  case learn::CandidateKind::Loop:
    return "loop " + std::to_string(c.iteration);
  case learn::CandidateKind::ForwardFit:
    return "forward fit " + std::to_string(c.iteration);
  case learn::CandidateKind::Network:
    return "network of iteration " + std::to_string(c.iteration);
  }
  return learn::to_string(c.kind);
}

nlohmann::json candidates_json(const learn::RecipeResult& result) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < result.candidates.size(); ++i) {
    const learn::Candidate& c = result.candidates[i];
    rows.push_back({ { "label", candidate_label(c) }, { "kind", learn::to_string(c.kind) },
        { "iteration", c.iteration }, { "completed", c.completed },
        { "validation_rms_m", measured(c.completed, c.validation.rms) },
        { "validation_max_m", measured(c.completed, c.validation.max) },
        // The recipe records the training error of the candidates the loop simulated (0: none).
        { "training_rms_m", measured(c.training.rms > 0, c.training.rms) },
        { "chosen", static_cast<int>(i) == result.chosen } });
  }
  return { { "validation_data", result.validation_data }, { "rows", rows } };
}

nlohmann::json frame_errors_panel(const std::string& title, const std::string& reference, double dt,
    const std::vector<ModelFrameErrors>& models) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& m : models) {
    rows.push_back({ { "label", m.label }, { "completed", m.completed }, { "max_m", m.errors.max },
        { "rms_m", m.errors.rms } });
  }
  return { { "title", title }, { "reference", reference }, { "dt", dt }, { "models", rows } };
}

nlohmann::json histograms_json(const std::string& reference, const std::vector<double>& edges,
    const std::vector<HistogramRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows)
    out.push_back({ { "label", r.label }, { "completed", r.completed }, { "counts", r.counts } });
  return { { "reference", reference }, { "bin_edges_m", edges }, { "rows", out } };
}

nlohmann::json correction_curves_json(const fem::MaterialModel& learned,
    const fem::MaterialModel* truth, const material::StretchRange* training) {
  double deviation = 0.1; // plots ±0.3 without a training range
  if (training && !training->empty())
    deviation = std::max(training->max.maxCoeff() - 1, 1 - training->min.minCoeff());
  const double half_width = std::clamp(3 * deviation, 0.05, 0.5);
  const int samples = 161;
  const material::StretchRange none;
  const material::StretchRange& range = training ? *training : none;
  fem::MaterialModel nominal = learned;
  nominal.correction = nullptr;

  nlohmann::json out;
  {
    const auto path = learn::uniaxial_path(1 - half_width, 1 + half_width, samples);
    std::vector<double> axial, lateral, truth_axial, truth_lateral;
    split_uniaxial(path, learn::stress_difference(path, learned, *learned.elastic), axial, lateral);
    if (truth) {
      split_uniaxial(path, learn::stress_difference(path, *truth, *learned.elastic), truth_axial,
          truth_lateral);
    }
    out["uniaxial"] = { { "stretch", path.x }, { "inside", learn::inside(path, range) },
      { "learned_axial", axial }, { "learned_lateral", lateral },
      { "truth_axial", truth ? nlohmann::json(truth_axial) : nlohmann::json(nullptr) },
      { "truth_lateral", truth ? nlohmann::json(truth_lateral) : nlohmann::json(nullptr) } };
  }
  {
    nlohmann::json paths = nlohmann::json::array();
    for (const auto& path : learn::deformation_scale_paths(half_width, samples)) {
      paths.push_back({ { "label", path.label }, { "scale", path.x },
          { "inside", learn::inside(path, range) },
          { "learned_norm", norms(learn::stress_difference(path, learned, *learned.elastic)) },
          { "truth_norm",
              truth
                  ? nlohmann::json(norms(learn::stress_difference(path, *truth, *learned.elastic)))
                  : nlohmann::json(nullptr) } });
    }
    out["deformation_scale"] = paths;
  }
  {
    const auto path = learn::largest_stretch_path(1 - half_width, 1 + half_width, samples);
    out["damping"] = { { "stretch", path.x }, { "inside", learn::inside(path, range) },
      { "nominal_alpha1", learn::stiffness_damping(path, nominal) },
      { "learned_alpha1", learn::stiffness_damping(path, learned) },
      { "truth_alpha1",
          truth ? nlohmann::json(learn::stiffness_damping(path, *truth))
                : nlohmann::json(nullptr) } };
  }
  out["has_truth"] = truth != nullptr;
  out["has_training_range"] = training && !training->empty();
  return out;
}

} // namespace elastolearn::io
