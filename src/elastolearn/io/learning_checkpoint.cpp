#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/nominal_parameters.hpp>

namespace elastolearn::io {

namespace {

constexpr const char* k_format = "elastolearn-learning-checkpoint";

nlohmann::json correction_json(const std::shared_ptr<const material::RbfCorrection>& c) {
  return c ? correction_to_json(*c) : nlohmann::json(nullptr);
}

std::shared_ptr<const material::RbfCorrection> read_correction(
    const JsonObject& object, const std::string& key) {
  if (object.json().at(key).is_null())
    return nullptr;
  auto c = correction_from_json(object.object(key));
  auto rbf = std::dynamic_pointer_cast<const material::RbfCorrection>(c);
  if (!rbf)
    object.fail(key, "must be an RBF correction");
  return rbf;
}

nlohmann::json error_json(const learn::ErrorSummary& e) {
  return { { "max", e.max }, { "mean", e.mean }, { "rms", e.rms }, { "worst_frame", e.worst_frame },
    { "worst_vertex", e.worst_vertex }, { "samples", e.samples } };
}

learn::ErrorSummary read_error(const JsonObject& o) {
  learn::ErrorSummary e;
  e.max = o.number("max");
  e.mean = o.number("mean");
  e.rms = o.number("rms");
  e.worst_frame = o.integer("worst_frame");
  e.worst_vertex = o.integer("worst_vertex");
  e.samples = static_cast<long>(o.number("samples"));
  return e;
}

learn::IterationRecord read_record(const JsonObject& o) {
  learn::IterationRecord r;
  r.iteration = o.integer("iteration");
  r.forward_error = read_error(o.object("forward_error"));
  r.forward_completed = o.boolean("forward_completed", true);
  r.forward_message = o.string("forward_message", "");
  r.forward_unstable = o.boolean("forward_unstable", false);
  r.damped_update = o.boolean("damped_update", false);
  r.forward_fit = o.boolean("forward_fit", false);
  r.forward_fit_accepted = o.boolean("forward_fit_accepted", false);
  r.control_force_rms = o.number("control_force_rms");
  r.space_time_initial = o.number("space_time_initial");
  r.space_time_objective = o.number("space_time_objective");
  r.space_time_iterations = o.integer("space_time_iterations");
  r.modes = o.integer("modes");
  r.centres = o.integer("centres");
  r.correction_misfit = o.number("correction_misfit");
  r.stability = o.number("stability", 0.0);
  r.step_kept = o.number("step_kept", 1.0);
  r.correction_target = o.number("correction_target");
  const JsonObject s = o.object("seconds");
  r.seconds_forward = s.number("forward");
  r.seconds_pod = s.number("pod");
  r.seconds_constrained = s.number("constrained");
  r.seconds_space_time = s.number("space_time");
  r.seconds_reconstruction = s.number("reconstruction");
  return r;
}

} // namespace

nlohmann::json iteration_record_to_json(const learn::IterationRecord& r) {
  return { { "iteration", r.iteration }, { "forward_error", error_json(r.forward_error) },
    { "forward_completed", r.forward_completed }, { "forward_message", r.forward_message },
    { "forward_unstable", r.forward_unstable }, { "damped_update", r.damped_update },
    { "forward_fit", r.forward_fit }, { "forward_fit_accepted", r.forward_fit_accepted },
    { "control_force_rms", r.control_force_rms }, { "space_time_initial", r.space_time_initial },
    { "space_time_objective", r.space_time_objective },
    { "space_time_iterations", r.space_time_iterations }, { "modes", r.modes },
    { "centres", r.centres }, { "correction_misfit", r.correction_misfit },
    { "stability", r.stability }, { "step_kept", r.step_kept },
    { "correction_target", r.correction_target },
    { "seconds",
        { { "forward", r.seconds_forward }, { "pod", r.seconds_pod },
            { "constrained", r.seconds_constrained }, { "space_time", r.seconds_space_time },
            { "reconstruction", r.seconds_reconstruction }, { "total", r.seconds_total() } } } };
}

nlohmann::json learning_options_to_json(const learn::LearningOptions& o) {
  return { { "max_iterations", o.max_iterations }, { "patience", o.patience },
    { "free_halvings", o.free_halvings },
    { "pod",
        { { "max_modes", o.pod.max_modes }, { "energy_fraction", o.pod.energy_fraction },
            { "first_frame", o.pod.first_frame }, { "frame_count", o.pod.frame_count },
            { "frame_stride", o.pod.frame_stride }, { "mass_orthonormal", o.pod.mass_orthonormal },
            { "with_constrained", o.pod_with_constrained } } },
    { "space_time",
        { { "position_weight", o.space_time.position_weight },
            { "max_iterations", o.space_time.max_iterations },
            { "tolerance", o.space_time.tolerance } } },
    { "centres", o.centres }, { "full_space", o.full_space },
    { "max_reconstruction_frames", o.max_reconstruction_frames },
    { "rbf",
        { { "epsilon", o.rbf.epsilon }, { "energy_kernels", o.rbf.energy_kernels },
            { "elastic_polynomial", o.rbf.elastic_polynomial },
            { "quadratic_tail", o.rbf.quadratic_tail },
            { "stress_free_rest", o.rbf.stress_free_rest },
            { "neo_hookean_tail", o.rbf.neo_hookean_tail }, { "fit_damping", o.rbf.fit_damping },
            { "damping_polynomial", o.rbf.damping_polynomial },
            { "damping_quadratic_tail", o.rbf.damping_quadratic_tail },
            { "regularization", o.rbf.regularization },
            { "damping_regularization", o.rbf.damping_regularization } } },
    { "reconstruction",
        { { "method", learn::reconstruction_method_name(o.reconstruction.method) },
            { "frame_stride", o.reconstruction.frame_stride },
            { "projected", o.projected_reconstruction },
            { "full_space_weight", o.reconstruction.full_space_weight } } },
    { "stretch_samples",
        { { "frame_stride", o.stretch_samples.frame_stride },
            { "max_samples", o.stretch_samples.max_samples } } },
    { "seed", o.seed },
    { "forward_fit",
        { { "max_iterations", o.forward_fit.max_iterations }, { "damping", o.forward_fit.damping },
            { "damping_prior", o.forward_fit.damping_prior },
            { "elastic_prior", o.forward_fit.elastic_prior } } } };
}

nlohmann::json recipe_options_to_json(const learn::RecipeOptions& o) {
  nlohmann::json fitted = nlohmann::json::array();
  for (auto p : o.parameter_fit.parameters)
    fitted.push_back(learn::to_string(p));
  return { { "noise", o.noise }, { "validation_fraction", o.validation_fraction },
    { "fit_parameters", o.fit_parameters },
    { "parameter_fit",
        { { "parameters", fitted }, { "max_iterations", o.parameter_fit.max_iterations },
            { "frames", o.parameter_fit.frames }, { "tolerance", o.parameter_fit.tolerance } } },
    { "loop", learning_options_to_json(o.loop) },
    { "network",
        { { "enabled", o.network.enabled },
            { "kind", o.network.kind ? material::to_string(*o.network.kind) : "auto" },
            { "motion_scales", o.network.motion_scales },
            { "recorded_samples", o.network.samples.recorded_samples },
            { "seed", o.network.samples.seed } } } };
}

namespace {

nlohmann::json parameter_fit_json(const learn::ParameterFitReport& f) {
  nlohmann::json j = { { "initial", to_json(f.initial) }, { "fitted", to_json(f.fitted) },
    { "initial_rms", f.initial_rms }, { "initial_max", f.initial_max },
    { "final_rms", f.final_rms }, { "final_max", f.final_max }, { "iterations", f.iterations },
    { "simulations", f.simulations }, { "diverged", f.diverged }, { "frames", f.frames },
    { "seconds", f.seconds }, { "stop", learn::to_string(f.stop) }, { "message", f.message } };
  if (f.tracked_with)
    j["tracked_with"] = to_json(*f.tracked_with);
  return j;
}

learn::NominalParameters read_parameters(const JsonObject& o) {
  return { o.number("young"), o.number("poisson"), o.number("alpha0"), o.number("alpha1") };
}

learn::ParameterFitReport read_parameter_fit(const JsonObject& o) {
  learn::ParameterFitReport f;
  f.initial = read_parameters(o.object("initial"));
  f.fitted = read_parameters(o.object("fitted"));
  f.initial_rms = o.number("initial_rms");
  f.initial_max = o.number("initial_max");
  f.final_rms = o.number("final_rms");
  f.final_max = o.number("final_max");
  f.iterations = o.integer("iterations");
  f.simulations = o.integer("simulations");
  f.diverged = o.integer("diverged");
  f.frames = o.integer("frames");
  f.seconds = o.number("seconds");
  const std::string stop = o.string("stop");
  for (auto s :
      { learn::FitStop::Converged, learn::FitStop::MaxIterations, learn::FitStop::NoImprovingStep,
          learn::FitStop::StartDiverged, learn::FitStop::Interrupted })
    if (learn::to_string(s) == stop)
      f.stop = s;
  f.message = o.string("message");
  if (o.has("tracked_with"))
    f.tracked_with = read_parameters(o.object("tracked_with"));
  return f;
}

} // namespace

void write_learning_checkpoint(const std::filesystem::path& path, const LearningInputs& inputs,
    const learn::RecipeResume& resume) {
  const learn::LearningState& state = resume.loop;
  nlohmann::json history = nlohmann::json::array();
  for (const auto& r : state.history)
    history.push_back(iteration_record_to_json(r));
  const nlohmann::json j = { { "format", std::string(k_format) + "/2" },
    { "inputs",
        { { "scene", inputs.scene }, { "observations", inputs.observations },
            { "options", inputs.options } } },
    { "parameter_fit", parameter_fit_json(resume.parameter_fit) },
    { "state",
        { { "next_iteration", state.next_iteration },
            { "correction", correction_json(state.correction) },
            { "best", correction_json(state.best) }, { "best_error", state.best_error },
            { "best_iteration", state.best_iteration },
            { "iterations_without_improvement", state.iterations_without_improvement },
            { "divergences_in_a_row", state.divergences_in_a_row }, { "finished", state.finished },
            { "forward_fit_steps", state.forward_fit_steps },
            { "forward_fit_damping", state.forward_fit_damping }, { "history", history } } } };
  write_json_file(path, j);
}

std::filesystem::path learning_checkpoint_path(
    const std::filesystem::path& output, const std::filesystem::path& checkpoint) {
  if (!checkpoint.empty())
    return checkpoint;
  std::filesystem::path path = output;
  path += ".checkpoint.json";
  return path;
}

learn::RecipeResume resume_learning_checkpoint(
    const std::filesystem::path& path, const LearningInputs& inputs, const std::string& option) {
  if (!std::filesystem::exists(path))
    throw InputError(
        path.string(), "no checkpoint to resume from (run without " + option + " first)");
  return read_learning_checkpoint(path, inputs);
}

learn::RecipeResume read_learning_checkpoint(
    const std::filesystem::path& path, const LearningInputs& inputs) {
  const nlohmann::json j = read_json_file(path);
  const JsonObject root(j, path.string());
  check_format(root, k_format, 2);
  const JsonObject in = root.object("inputs");
  if (in.string("scene") != inputs.scene)
    in.fail("scene",
        "the checkpoint belongs to scene '" + in.string("scene") + "', not '" + inputs.scene + "'");
  if (in.string("observations") != inputs.observations)
    in.fail("observations",
        "the checkpoint belongs to observations '" + in.string("observations") + "', not '"
            + inputs.observations + "'");
  if (in.json().at("options") != inputs.options)
    in.fail("options",
        "the checkpoint was made with other learning options: resume with the same options");
  learn::RecipeResume resume;
  resume.parameter_fit = read_parameter_fit(root.object("parameter_fit"));
  const JsonObject s = root.object("state");
  learn::LearningState& state = resume.loop;
  state.next_iteration = s.integer("next_iteration");
  state.correction = read_correction(s, "correction");
  state.best = read_correction(s, "best");
  state.best_error = s.number("best_error");
  state.best_iteration = s.integer("best_iteration");
  state.iterations_without_improvement = s.integer("iterations_without_improvement");
  state.divergences_in_a_row = s.integer("divergences_in_a_row");
  state.finished = s.boolean("finished", false);
  state.forward_fit_steps = s.integer("forward_fit_steps");
  state.forward_fit_damping = s.number("forward_fit_damping");
  for (const auto& r : s.objects("history"))
    state.history.push_back(read_record(r));
  return resume;
}

} // namespace elastolearn::io
