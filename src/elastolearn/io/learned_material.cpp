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

/// Distil `teacher` into the network correction on states of the training scene at several
/// motion amplitudes; report the fit through `message`; the network's provenance as JSON.
std::shared_ptr<const material::Correction> distil_network(const NetworkDistillation& o,
    const sim::Scene& scene, const material::Correction& teacher,
    const std::function<void(const std::string&)>& message, nlohmann::json& provenance) {
  const auto start = Clock::now();
  learn::DistillationSampleReport sampled;
  const learn::StressSamples samples
      = learn::distillation_samples(scene, o.motion_scales, teacher, o.samples, &sampled);
  const double seconds_sampling = seconds_since(start);
  if (message)
    for (const auto& m : sampled.messages)
      message("network samples: " + m);
  const auto* rbf = dynamic_cast<const material::RbfCorrection*>(&teacher);
  const bool energy
      = o.kind == "energy" || (o.kind == "auto" && rbf && rbf->parameters().energy_kernels);
  learn::NnDistillationOptions training
      = energy ? learn::energy_distillation_options() : o.training;
  if (energy && rbf) // the teacher's tails as the energy's polynomial (docs/learning.md)
    training.energy_polynomial = learn::rbf_energy_polynomial(*rbf);
  const learn::NnDistillationResult r = learn::distill_nn_correction(samples, training);
  if (message) {
    char line[512];
    std::snprintf(line, sizeof line,
        "network (%s): %d + %d states (%d recorded of %ld, %d jittered; %d/%zu motions "
        "completed), %d epochs; RMS relative to the RBF teacher: training %.2f %%, validation "
        "%.2f %% (teacher RMS %.4g Pa); sampling %.1f s, training %.1f s",
        material::to_string(training.kind).c_str(), r.training_samples, r.validation_samples,
        sampled.recorded, sampled.states_seen, sampled.jittered, sampled.scenes_completed,
        o.motion_scales.size(), r.training.epochs, 100 * r.relative_training_rms(),
        100 * r.relative_validation_rms(), r.target_rms, seconds_sampling, r.training.seconds);
    message(line);
  }
  provenance = { { "teacher", correction_to_json(teacher) },
    { "network",
        { { "kind", material::to_string(training.kind) }, { "motion_scales", o.motion_scales },
            { "recorded_states", sampled.recorded }, { "jittered_states", sampled.jittered },
            { "training_states", r.training_samples },
            { "validation_states", r.validation_samples }, { "epochs", r.training.epochs },
            { "training_rms_pa", r.training_rms }, { "validation_rms_pa", r.validation_rms },
            { "teacher_rms_pa", r.target_rms }, { "seconds_sampling", seconds_sampling },
            { "seconds_training", r.training.seconds } } } };
  return std::make_shared<const material::NnCorrection>(
      learn::with_teacher_damping(r.correction, teacher));
}

} // namespace

nlohmann::json recipe_result_to_json(const learn::RecipeResult& r) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const auto& c : r.candidates)
    candidates.push_back({ { "kind", learn::to_string(c.kind) }, { "iteration", c.iteration },
        { "completed", c.completed }, { "training_rms_error_m", c.training.rms },
        { "validation_rms_error_m", c.completed ? nlohmann::json(c.validation.rms) : nullptr },
        { "validation_max_error_m", c.completed ? nlohmann::json(c.validation.max) : nullptr },
        { "extrapolation_unstable_samples", c.extrapolation.unstable_samples },
        { "extrapolation_samples", c.extrapolation.samples }, { "eligible", c.eligible() },
        // null: infinite (noise σ = 0 and it is better than the reference)
        { "significance",
            std::isfinite(c.significance) ? nlohmann::json(c.significance) : nullptr } });
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

MaterialFile learned_material_file(const TrainingSet& set, const std::string& source,
    const learn::RecipeResult& result, const learn::RecipeOptions& options,
    const NetworkDistillation& network, const std::function<void(const std::string&)>& message) {
  const learn::Candidate& chosen = result.choice();
  const sim::Scene& scene = set.motions.front().scene;
  double loop_seconds = 0;
  nlohmann::json history = nlohmann::json::array();
  for (const auto& r : result.loop.history) {
    loop_seconds += r.seconds_total();
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
    motion_names.push_back(
        { { "scene", f.paths.scene.string() }, { "observations", f.paths.observations.string() } });
  learned.training = { { set.path.empty() ? "scene" : "training_set", source },
    { "motions", motion_names }, { "observed_vertices", set.motions[0].observed.num_observed() },
    { "best_iteration", result.loop.best_iteration },
    { "best_rms_error_m", result.loop.best_error }, { "options", recipe_options_to_json(options) },
    { "recipe", recipe_result_to_json(result) }, { "seconds", result.seconds },
    { "loop_seconds", loop_seconds }, { "history", history } };
  if (network.enabled && chosen.correction) {
    nlohmann::json provenance;
    learned.correction
        = distil_network(network, training_scene, *chosen.correction, message, provenance);
    learned.training["teacher"] = provenance["teacher"]; // the RBF, so that nothing is lost
    learned.training["network"] = provenance["network"];
  }
  return learned;
}

} // namespace elastolearn::io
