#include <elastolearn/core/timing.hpp>
#include <elastolearn/io/learned_material.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/io/nominal_parameters.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <cmath>
#include <cstdio>

namespace elastolearn::io {

namespace {

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nullptr;
}

/// Stage 5's distillation, as the learned file's training.network.
nlohmann::json network_to_json(const learn::NetworkDistillation& d, bool chosen) {
  return { { "kind", material::to_string(d.kind) }, { "chosen", chosen },
    { "motion_amplitudes", d.motions }, { "recorded_states", d.sampled.recorded },
    { "jittered_states", d.sampled.jittered }, { "training_states", d.training_states },
    { "validation_states", d.validation_states }, { "epochs", d.epochs },
    { "training_rms_pa", d.training_rms }, { "validation_rms_pa", d.validation_rms },
    { "teacher_rms_pa", d.teacher_rms }, { "seconds_sampling", d.seconds_sampling },
    { "seconds_training", d.seconds_training } };
}

/// null for a candidate not checked (the nominals, and a correction ranked below the chosen one).
nlohmann::json larger_motion_to_json(const learn::LargerMotionCheck& l) {
  if (!l.checked)
    return nullptr;
  return { { "factor", learn::kLargerMotion }, { "completed", l.completed },
    { "message", l.message }, { "first_substepped_frame", l.first_substepped_frame } };
}

/// null for a candidate not checked (the nominals, and a correction whose validation diverged).
nlohmann::json stability_to_json(const learn::StabilityReport& s) {
  if (s.samples == 0)
    return nullptr;
  return { { "samples", s.samples }, { "unstable_samples", s.unstable_samples },
    { "min_relative_eigenvalue", s.min_relative_eigenvalue },
    { "worst_stretches", { s.worst_stretches(0), s.worst_stretches(1), s.worst_stretches(2) } } };
}

} // namespace

nlohmann::json recipe_result_to_json(const learn::RecipeResult& r) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const auto& c : r.candidates) {
    candidates.push_back({ { "kind", learn::to_string(c.kind) }, { "iteration", c.iteration },
        { "completed", c.completed }, { "training_rms_error_m", finite_or_null(c.training.rms) },
        { "validation_rms_error_m", c.completed ? nlohmann::json(c.validation.rms) : nullptr },
        { "validation_max_error_m", c.completed ? nlohmann::json(c.validation.max) : nullptr },
        { "larger_motion", larger_motion_to_json(c.larger_motion) },
        { "reachable_stretches", stability_to_json(c.stability) },
        // null: a correction ranked below the chosen candidate, whose larger motion was not run
        { "eligible",
            c.correction && c.completed && !c.larger_motion.checked
                ? nlohmann::json(nullptr)
                : nlohmann::json(c.eligible()) },
        // null: infinite (noise σ = 0), its sign that of the validation errors' difference
        { "significance", finite_or_null(c.significance) },
        // the z an exactly right candidate would reach on the held-out data; null: infinite
        { "resolution", finite_or_null(c.resolution) }, { "unknowns", c.unknowns },
        // null: not measured, or infinite (noise σ = 0)
        { "training_significance", finite_or_null(c.training_significance) },
        // the z it had to reach to beat the reference (0: not compared with one)
        { "required_significance", c.required_significance },
        { "beats_reference", c.beats_reference } });
    if (!c.completed)
      candidates.back()["failure"] = c.failure;
    if (c.kind == learn::CandidateKind::Network) {
      candidates.back()["teacher"] = c.teacher;
      candidates.back()["gain_over_teacher"] = finite_or_null(c.gain_over_teacher);
    }
  }
  return { { "noise_sigma_m", r.noise.sigma }, { "noise_estimated", r.noise.estimated },
    { "smoothing_rms_change_m", r.noise.smoothing_residual },
    { "training_frames", r.training_frames }, { "validation_frames", r.validation_frames },
    { "validation_data", r.validation_data },
    { "parameter_fit",
        { { "initial", to_json(r.parameter_fit.initial) },
            { "fitted", to_json(r.parameter_fit.fitted) },
            { "initial_rms_error_m", r.parameter_fit.initial_rms },
            { "final_rms_error_m", r.parameter_fit.final_rms },
            { "iterations", r.parameter_fit.iterations },
            { "seconds", r.parameter_fit.seconds } } },
    { "candidates", candidates }, { "chosen", r.chosen },
    { "chosen_kind", learn::to_string(r.choice().kind) } };
}

void add_network_provenance(nlohmann::json& training, const learn::RecipeResult& result) {
  if (!result.network)
    return;
  const learn::Candidate& chosen = result.choice();
  const bool network = chosen.kind == learn::CandidateKind::Network;
  training["network"] = network_to_json(*result.network, network);
  if (network) // the RBF, so that nothing is lost
    training["teacher"]
        = correction_to_json(*result.candidates.at(static_cast<size_t>(chosen.teacher)).correction);
}

MaterialFile learned_material_file(const TrainingSet& set, const std::string& source,
    const learn::RecipeResult& result, const learn::RecipeOptions& options) {
  const learn::Candidate& chosen = result.choice();
  const sim::Scene& scene = set.motions.front().scene;
  double loop_seconds = 0;
  nlohmann::json history = nlohmann::json::array();
  for (const auto& r : result.loop.history) {
    loop_seconds += learn::seconds_of(r);
    history.push_back(iteration_record_to_json(r));
  }
  MaterialFile learned;
  learned.material = chosen.kind == learn::CandidateKind::Nominal
      ? set.nominal_material
      : with_nominal_parameters(
          set.nominal_material, result.parameter_fit.fitted, options.fit_parameters);
  learned.correction = chosen.correction;
  sim::Scene training_scene = scene;
  training_scene.material = result.material(scene.material);
  training_scene.material.correction = nullptr;
  learned.training_stretches = learn::training_stretch_range(training_scene, chosen.correction);
  nlohmann::json motion_names = nlohmann::json::array();
  for (const auto& f : set.files)
    motion_names.push_back({ { "scene", f.paths.scene.string() },
        f.paths.clouds.empty() ? nlohmann::json { "observations", f.paths.observations.string() }
                               : nlohmann::json { "clouds", f.paths.clouds.string() } });
  learned.training = { { set.path.empty() ? "scene" : "training_set", source },
    { "motions", motion_names }, { "observed_vertices", result.observed.at(0).num_observed() },
    { "best_iteration", result.loop.best_iteration },
    { "best_rms_error_m", result.loop.best_error }, { "options", recipe_options_to_json(options) },
    { "recipe", recipe_result_to_json(result) }, { "seconds", result.seconds },
    { "loop_seconds", loop_seconds }, { "history", history } };
  add_network_provenance(learned.training, result);
  return learned;
}

} // namespace elastolearn::io
