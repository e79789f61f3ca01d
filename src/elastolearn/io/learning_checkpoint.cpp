#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/nominal_parameters.hpp>

namespace elastolearn::io {

namespace {

constexpr const char* k_format = "elastolearn-learning-checkpoint";
/// The version written. Version 3 writes one record per kind of step (iteration_record_to_json);
/// versions 1 and 2 wrote flat records with flags, still read (read_flat_record).
constexpr int k_checkpoint_version = 3;

/// A checkpoint's options with the fields added since it was written set to the values every run
/// had before (so that it still resumes under those options): rbf.smoothness 0,
/// rbf.continuation bounded_softening, rbf.mass_damping false, backtrack false,
/// forward_fit.function_tolerance 0, stability_cuts and forward_fit.stability_cuts false.
nlohmann::json with_former_defaults(nlohmann::json options) {
  const auto fill = [](nlohmann::json& loop) {
    if (!loop.is_object())
      return;
    if (loop.contains("rbf") && loop["rbf"].is_object() && !loop["rbf"].contains("smoothness"))
      loop["rbf"]["smoothness"] = 0.0;
    if (loop.contains("rbf") && loop["rbf"].is_object() && !loop["rbf"].contains("continuation"))
      loop["rbf"]["continuation"] = "bounded_softening";
    if (loop.contains("rbf") && loop["rbf"].is_object() && !loop["rbf"].contains("mass_damping"))
      loop["rbf"]["mass_damping"] = false;
    // "patience" marks the loop's object (the recipe's options hold it under "loop").
    if (loop.contains("patience") && !loop.contains("backtrack"))
      loop["backtrack"] = false;
    if (loop.contains("patience") && !loop.contains("stability_cuts"))
      loop["stability_cuts"] = false;
    if (loop.contains("forward_fit") && loop["forward_fit"].is_object()) {
      if (!loop["forward_fit"].contains("function_tolerance"))
        loop["forward_fit"]["function_tolerance"] = 0.0;
      if (!loop["forward_fit"].contains("stability_cuts"))
        loop["forward_fit"]["stability_cuts"] = false;
    }
  };
  fill(options);
  if (options.is_object() && options.contains("loop"))
    fill(options["loop"]);
  return options;
}

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

/// A loop record's trajectory stages; `seconds` holds their times. Versions 1 and 2 (`flat`) may
/// lack "stability" and "step_kept" (0: not checked, 1: all kept).
learn::SpaceTimeStages read_stages(
    const JsonObject& o, const JsonObject& seconds, bool flat = false) {
  learn::SpaceTimeStages t;
  t.modes = o.integer("modes");
  t.control_force_rms = o.number("control_force_rms");
  t.space_time_initial = o.number("space_time_initial");
  t.space_time_objective = o.number("space_time_objective");
  t.space_time_iterations = o.integer("space_time_iterations");
  t.centres = o.integer("centres");
  t.correction_misfit = o.number("correction_misfit");
  t.correction_target = o.number("correction_target");
  t.stability = flat ? o.number("stability", 0.0) : o.number("stability");
  t.step_kept = flat ? o.number("step_kept", 1.0) : o.number("step_kept");
  t.stability_cuts = o.integer("stability_cuts", 0); // absent before the cuts: none
  t.seconds_pod = seconds.number("pod");
  t.seconds_constrained = seconds.number("constrained");
  t.seconds_space_time = seconds.number("space_time");
  t.seconds_reconstruction = seconds.number("reconstruction");
  return t;
}

/// A record of a version-1 or -2 checkpoint: one flat object with flags for the kind of step
/// ("forward_fit", "forward_completed", "forward_unstable", "damped_update") and every field,
/// zero where it was not measured. A loop iteration ran the trajectory stages when it has modes
/// or kernels (both are 0 in a record without them).
learn::IterationRecord read_flat_record(const JsonObject& o) {
  const int iteration = o.integer("iteration");
  const JsonObject s = o.object("seconds");
  const double seconds_forward = s.number("forward");
  const learn::ForwardOutcome forward = o.boolean("forward_completed", true)
      ? learn::ForwardOutcome::completed(read_error(o.object("forward_error")), seconds_forward)
      : o.boolean("forward_unstable", false)
      ? learn::ForwardOutcome::unstable(o.string("forward_message", ""), seconds_forward)
      : learn::ForwardOutcome::diverged(o.string("forward_message", ""), seconds_forward);
  if (o.boolean("forward_fit", false))
    return learn::ForwardFitRecord { iteration, forward, o.boolean("forward_fit_accepted", false),
      o.integer("centres") };
  learn::LoopNext next = learn::LoopEnd {};
  if (!forward.completed()) {
    if (o.boolean("damped_update", false))
      next = learn::DampedUpdate {};
  } else if (o.integer("modes") > 0 || o.integer("centres") > 0) {
    next = read_stages(o, s, true);
  }
  return learn::LoopRecord { iteration, forward, next };
}

nlohmann::json forward_json(const learn::ForwardOutcome& f) {
  nlohmann::json j = { { "status", learn::to_string(f.status()) } };
  if (f.completed())
    j["error"] = error_json(f.error());
  else
    j["message"] = f.message();
  return j;
}

learn::ForwardOutcome read_forward(const JsonObject& o, double seconds) {
  const std::string status = o.choice("status", { "completed", "diverged", "unstable" });
  switch (*learn::forward_status_from_string(status)) {
  case learn::ForwardStatus::completed:
    return learn::ForwardOutcome::completed(read_error(o.object("error")), seconds);
  case learn::ForwardStatus::diverged:
    return learn::ForwardOutcome::diverged(o.string("message"), seconds);
  case learn::ForwardStatus::unstable:
    break;
  }
  return learn::ForwardOutcome::unstable(o.string("message"), seconds);
}

nlohmann::json stages_json(const learn::SpaceTimeStages& t) {
  return { { "modes", t.modes }, { "control_force_rms", t.control_force_rms },
    { "space_time_initial", t.space_time_initial },
    { "space_time_objective", t.space_time_objective },
    { "space_time_iterations", t.space_time_iterations }, { "centres", t.centres },
    { "correction_misfit", t.correction_misfit }, { "correction_target", t.correction_target },
    { "stability", t.stability }, { "step_kept", t.step_kept },
    { "stability_cuts", t.stability_cuts } };
}

/// The names of LoopNext's alternatives (a loop record's "next").
constexpr const char* k_space_time = "space_time";
constexpr const char* k_damped_update = "damped_update";
constexpr const char* k_end = "end";

/// A record of a version-3 checkpoint (iteration_record_to_json).
learn::IterationRecord read_record(const JsonObject& o) {
  const int iteration = o.integer("iteration");
  const JsonObject seconds = o.object("seconds");
  const learn::ForwardOutcome forward
      = read_forward(o.object("forward"), seconds.number("forward"));
  if (o.choice("kind", { "loop", "forward_fit" }) == "forward_fit")
    return learn::ForwardFitRecord { iteration, forward, o.boolean("accepted", false),
      o.integer("centres") };
  const std::string next = o.choice("next", { k_space_time, k_damped_update, k_end });
  if (next == k_space_time)
    return learn::LoopRecord { iteration, forward, read_stages(o.object("stages"), seconds) };
  if (next == k_damped_update)
    return learn::LoopRecord { iteration, forward, learn::DampedUpdate {} };
  return learn::LoopRecord { iteration, forward, learn::LoopEnd {} };
}

} // namespace

nlohmann::json iteration_record_to_json(const learn::IterationRecord& record) {
  const learn::ForwardOutcome& forward = learn::forward_of(record);
  nlohmann::json j
      = { { "iteration", learn::iteration_of(record) }, { "forward", forward_json(forward) } };
  nlohmann::json seconds = { { "forward", forward.seconds() } };
  if (const learn::ForwardFitRecord* step = learn::forward_fit_of(record)) {
    j["kind"] = "forward_fit";
    j["accepted"] = step->accepted;
    j["centres"] = step->centres;
  } else {
    const auto& loop = std::get<learn::LoopRecord>(record);
    j["kind"] = "loop";
    if (const learn::SpaceTimeStages* t = loop.stages()) {
      j["next"] = k_space_time;
      j["stages"] = stages_json(*t);
      seconds["pod"] = t->seconds_pod;
      seconds["constrained"] = t->seconds_constrained;
      seconds["space_time"] = t->seconds_space_time;
      seconds["reconstruction"] = t->seconds_reconstruction;
    } else {
      j["next"] = loop.damped_update() ? k_damped_update : k_end;
    }
  }
  seconds["total"] = learn::seconds_of(record);
  j["seconds"] = seconds;
  return j;
}

nlohmann::json learning_options_to_json(const learn::LearningOptions& o) {
  return { { "max_iterations", o.max_iterations }, { "patience", o.patience },
    { "free_halvings", o.free_halvings }, { "backtrack", o.backtrack },
    { "stability_cuts", o.stability_cuts },
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
            { "damping_regularization", o.rbf.damping_regularization },
            { "smoothness", o.rbf.smoothness },
            { "continuation", material::continuation_name(o.rbf.continuation) },
            { "mass_damping", o.rbf.mass_damping } } },
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
            { "elastic_prior", o.forward_fit.elastic_prior },
            { "function_tolerance", o.forward_fit.function_tolerance },
            { "stability_cuts", o.forward_fit.stability_cuts } } } };
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
    { "simulations", f.simulations }, { "diverged", f.diverged },
    { "unheld_loads", f.unheld_loads }, { "frames", f.frames }, { "seconds", f.seconds },
    { "stop", learn::to_string(f.stop) }, { "message", f.message } };
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
  if (o.has("unheld_loads")) // checkpoints written before the count have none
    f.unheld_loads = o.integer("unheld_loads");
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
  nlohmann::json tried = nlohmann::json::array();
  for (const auto& [iteration, correction] : state.tried)
    tried.push_back({ { "iteration", iteration }, { "correction", correction_json(correction) } });
  const nlohmann::json j
      = { { "format", std::string(k_format) + "/" + std::to_string(k_checkpoint_version) },
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
                  { "failed_steps_in_a_row", state.failed_steps_in_a_row },
                  { "finished", state.finished }, { "forward_fit_steps", state.forward_fit_steps },
                  { "forward_fit_damping", state.forward_fit_damping },
                  { "forward_fit_converged", state.forward_fit_converged }, { "history", history },
                  { "tried", tried } } } };
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
  const int version = check_format(root, k_format, k_checkpoint_version);
  const JsonObject in = root.object("inputs");
  if (in.string("scene") != inputs.scene)
    in.fail("scene",
        "the checkpoint belongs to scene '" + in.string("scene") + "', not '" + inputs.scene + "'");
  if (in.string("observations") != inputs.observations)
    in.fail("observations",
        "the checkpoint belongs to observations '" + in.string("observations") + "', not '"
            + inputs.observations + "'");
  if (with_former_defaults(in.json().at("options")) != inputs.options)
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
  // Checkpoints written before backtracking counted divergences only, under their own name.
  state.failed_steps_in_a_row = s.has("failed_steps_in_a_row") ? s.integer("failed_steps_in_a_row")
                                                               : s.integer("divergences_in_a_row");
  state.finished = s.boolean("finished", false);
  state.forward_fit_steps = s.integer("forward_fit_steps");
  state.forward_fit_damping = s.number("forward_fit_damping");
  state.forward_fit_converged = s.boolean("forward_fit_converged", false);
  for (const auto& r : s.objects("history"))
    state.history.push_back(version >= 3 ? read_record(r) : read_flat_record(r));
  // Older checkpoints kept the best correction only.
  if (s.has("tried"))
    for (const auto& t : s.objects("tried"))
      state.tried[t.integer("iteration")] = read_correction(t, "correction");
  return resume;
}

} // namespace elastolearn::io
