#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/learning_stages.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace elastolearn::learn {

void LearningOptions::validate() const {
  if (max_iterations < 0)
    throw InputError("learn.max_iterations", "must be ≥ 0");
  if (patience < 1)
    throw InputError("learn.patience", "must be ≥ 1");
  if (free_halvings < 0)
    throw InputError("learn.free_halvings", "must be ≥ 0");
  if (centres < 1)
    throw InputError("learn.centres", "must be ≥ 1");
  pod.validate();
  space_time.validate();
  rbf.validate();
  reconstruction.validate();
  stretch_samples.validate();
  forward_fit.validate();
  if (max_reconstruction_frames < 0)
    throw InputError("learn.max_reconstruction_frames", "must be ≥ 0");
  if (full_space && max_full_space_dofs < 1)
    throw InputError("learn.max_full_space_dofs", "must be ≥ 1");
}

namespace {

/// The field name of motion i in messages: the single-motion name for one motion.
std::string motion_field(std::span<const Motion> motions, size_t i, const std::string& field) {
  return motions.size() == 1 ? field : "motions[" + std::to_string(i) + "]." + field;
}

/// √ of the weighted mean of two mean squares a², b² with weights wa, wb.
double merged_rms(double a, double wa, double b, double wb) {
  return std::sqrt((wa * a * a + wb * b * b) / (wa + wb));
}

/// The control-force RMS of a step (0 without trajectory stages).
double control_force_rms(const IterationRecord& record) {
  const SpaceTimeStages* stages = stages_of(record);
  return stages ? stages->control_force_rms : 0.0;
}

/// The last iteration's control-force RMS is below 95 % of every earlier one.
bool control_forces_still_shrinking(const std::vector<IterationRecord>& history) {
  if (history.size() < 2)
    return false;
  const double last = control_force_rms(history.back());
  for (size_t i = 0; i + 1 < history.size(); ++i)
    if (!(last < 0.95 * control_force_rms(history[i])))
      return false;
  return last > 0;
}

/// What the loop holds for the whole run: each motion's setup and reconstruction mesh.
struct LoopSetup {
  std::deque<MotionSetup> motions; ///< in place: see MotionSetup
  std::vector<ReconstructionMesh> meshes;
  StressReconstructionOptions reconstruction;
};

/// Validates the inputs (InputError naming the motion's field) and precomputes the setups.
void set_up(std::span<const Motion> motions, const LearningOptions& options, LoopSetup& setup) {
  options.validate();
  if (motions.empty())
    throw InputError("motions", "no motion to learn from");
  for (size_t i = 0; i < motions.size(); ++i) {
    const sim::Scene& scene = motions[i].scene;
    scene.validate();
    if (scene.material.correction)
      throw InputError(motion_field(motions, i, "material"),
          "the nominal scene must not carry a correction already");
    motions[i].observed.validate(scene.mesh.num_vertices(), scene.frames + 1, scene.dt,
        motion_field(motions, i, "observations"));
    if (motions[i].smoothed)
      motions[i].smoothed->validate(scene.mesh.num_vertices(), scene.frames + 1, scene.dt,
          motion_field(motions, i, "smoothed observations"));
  }
  // The learned Δα₁ may lower the nominal damping; fem::ElasticForce keeps α₁ + Δα₁ ≥ 0.
  setup.meshes.reserve(motions.size());
  int longest = 0; // frames of the longest motion
  for (size_t i = 0; i < motions.size(); ++i) {
    const sim::Scene& scene = motions[i].scene;
    setup.meshes.emplace_back(scene.mesh, scene.material);
    const MotionSetup& motion = setup.motions.emplace_back(motions[i]);
    if (options.full_space
        && 3 * static_cast<long>(motion.basis_vertices.size()) > options.max_full_space_dofs)
      throw InputError(motion_field(motions, i, "learn.full_space"),
          "the full-space variant solves dense " + std::to_string(3 * motion.basis_vertices.size())
              + "² blocks per frame; it is meant for meshes up to "
              + std::to_string(options.max_full_space_dofs)
              + " free dofs: use the reduced (POD) variant");
    longest = std::max(longest, scene.frames);
  }
  setup.reconstruction = reconstruction_options(options, longest);
}

/// The state after iteration k's forward simulation `forward` (the loop's bookkeeping): the
/// corrections tried, the best one, the patience and failed-step counters, and whether the loop
/// ends. Progress is a
/// better forward error, or (paper §3) control forces that still shrink clearly although the
/// forward error does not show it yet; the best correction is chosen by the former.
LearningState after_forward(
    const LearningState& state, const ForwardOutcome& forward, const LearningOptions& options) {
  LearningState next = state;
  const int k = state.next_iteration;
  const bool completed = forward.completed();
  const double error = completed ? forward.error().rms : std::numeric_limits<double>::infinity();
  const bool better_forward = completed && (next.best_error < 0 || error < next.best_error);
  if (completed && state.correction)
    next.tried[k] = state.correction;
  if (better_forward) {
    next.best = state.correction;
    next.best_error = error;
    next.best_iteration = k;
  }
  const bool overshot = !completed || (options.backtrack && !better_forward);
  next.failed_steps_in_a_row = overshot ? state.failed_steps_in_a_row + 1 : 0;
  if (better_forward
      || (completed && !options.backtrack && control_forces_still_shrinking(state.history)))
    next.iterations_without_improvement = 0;
  else if (next.failed_steps_in_a_row == 0 || next.failed_steps_in_a_row > options.free_halvings)
    ++next.iterations_without_improvement;
  if (next.iterations_without_improvement >= options.patience || k >= options.max_iterations)
    next.finished = true;
  return next;
}

/// ½ (c + best), either of them null for the nominal; null when both are: C_k is then the
/// nominal itself (its reconstruction was dropped as unstable) and so is the best, and there is
/// no step to shorten.
std::shared_ptr<const material::RbfCorrection> halfway(
    const std::shared_ptr<const material::RbfCorrection>& c,
    const std::shared_ptr<const material::RbfCorrection>& best) {
  if (!c && !best)
    return nullptr;
  return std::make_shared<material::RbfCorrection>(
      c ? material::blend(*c, best.get(), 0.5) : material::blend(*best, nullptr, 0.5));
}

/// What stages 2–6 give: C_{k+1} and their record.
struct TrajectoryStagesResult {
  SpaceTimeStages record;
  std::shared_ptr<const material::RbfCorrection> correction;
};

/// Stages 2–6 of iteration k from `forward` (stage 1's runs of `correction`, all completed):
/// per motion, each with its own mesh and basis, the constrained simulation, POD, space-time
/// optimisation and control forces; then one reconstruction over every motion. The record sums
/// over the motions (control_force_rms is the RMS over all motions' steps and free dofs).
/// nullopt if interrupted.
std::optional<TrajectoryStagesResult> trajectory_stages(std::span<const Motion> motions,
    LoopSetup& setup, const ForwardStage& forward,
    const std::shared_ptr<const material::RbfCorrection>& correction,
    const LearningOptions& options, int k, const LearningCallbacks& callbacks) {
  auto interrupted = [&] { return callbacks.interrupted && callbacks.interrupted(); };
  TrajectoryStagesResult out;
  SpaceTimeStages& record = out.record;
  std::deque<OptimizedMotion> optimized_motions;
  double control_weight = 0;
  for (size_t i = 0; i < motions.size(); ++i) {
    const sim::Scene& scene = motions[i].scene;
    MotionSetup& motion = setup.motions[i];
    const sim::ForwardRun& run = forward.runs[i];
    if (interrupted())
      return std::nullopt;
    auto t0 = Clock::now();
    const sim::ForwardRun constrained
        = constrained_simulation(motion, run, correction, callbacks.progress);
    record.seconds_constrained += seconds_since(t0);

    t0 = Clock::now();
    const PodBasis basis = trajectory_basis(scene, motion, run, constrained, options);
    record.modes += basis.num_modes();
    record.seconds_pod += seconds_since(t0);

    t0 = Clock::now();
    const std::vector<VecX> origin = space_time_origin(run, constrained, basis);
    record.seconds_constrained += seconds_since(t0);
    if (interrupted())
      return std::nullopt;

    t0 = Clock::now();
    OptimizedMotion& optimized_motion
        = optimized_motions.emplace_back(sim::with_correction(scene, correction));
    SpaceTimeResult optimized = optimize_space_time(optimized_motion.physics, basis.modes, origin,
        run.initial_velocity, motions[i].followed(), options.space_time, callbacks.progress);
    record.space_time_initial += optimized.initial_objective;
    record.space_time_objective += optimized.objective;
    record.space_time_iterations += optimized.iterations;
    const double weight = double(scene.frames)
        * double(optimized_motion.physics.dofs().num_free()); // steps × free dofs
    record.control_force_rms = i == 0
        ? optimized.physics_rms
        : merged_rms(record.control_force_rms, control_weight, optimized.physics_rms, weight);
    control_weight += weight;
    record.seconds_space_time += seconds_since(t0);

    t0 = Clock::now();
    reconstruction_inputs(motion, std::move(optimized.positions), run.initial_velocity, scene.dt,
        basis, options, optimized_motion);
    record.seconds_reconstruction += seconds_since(t0);
  }
  if (interrupted())
    return std::nullopt;

  const auto t0 = Clock::now();
  Reconstruction reconstructed
      = reconstruct_correction(setup.meshes, optimized_motions, motions.front().scene.material,
          options, setup.reconstruction, options.seed + static_cast<std::uint64_t>(k));
  record.centres = reconstructed.centres;
  record.correction_misfit = reconstructed.misfit;
  record.correction_target = reconstructed.target;
  record.stability = reconstructed.stability;
  record.step_kept = reconstructed.step_kept;
  record.stability_cuts = static_cast<int>(reconstructed.stability_cuts);
  out.correction = std::move(reconstructed.correction);
  record.seconds_reconstruction += seconds_since(t0);
  return out;
}

/// The stage after the loop: Levenberg–Marquardt on the forward error summed over the motions
/// from the best correction (LearningOptions::forward_fit). Each step is one ForwardFitRecord and
/// one checkpoint; a resumed run restarts from the best correction with the saved μ, so it takes
/// the same steps.
bool run_forward_fit(std::span<const Motion> motions, std::span<const ReconstructionMesh> meshes,
    const LearningOptions& options, LearningState& state, const LearningCallbacks& callbacks) {
  const int remaining = options.forward_fit.max_iterations - state.forward_fit_steps;
  if (remaining <= 0 || state.forward_fit_converged)
    return true;
  if (callbacks.interrupted && callbacks.interrupted())
    return false;
  const ForwardFitStart fit = forward_fit_start(motions, meshes, state.best, options, remaining,
      state.forward_fit_damping, callbacks.progress);
  bool stopped = false;
  const ForwardFitResult result = fit_to_observations(motions, meshes, fit.design, fit.start,
      fit.options, callbacks.progress,
      [&](const ForwardSensitivityPass& trial, bool accepted, const VecX& kept, double damping) {
        const ForwardFitRecord record
            = forward_fit_record(state.next_iteration, trial, accepted, fit.design);
        // The kept unknowns are the best correction (the start's, until a step is accepted).
        state.correction = std::make_shared<material::RbfCorrection>(fit.design.correction(kept));
        if (accepted) {
          state.tried[record.iteration] = state.correction;
          state.best = state.correction;
          state.best_error = trial.error.rms;
          state.best_iteration = record.iteration;
        }
        ++state.forward_fit_steps;
        state.forward_fit_damping = damping;
        state.next_iteration = record.iteration + 1;
        state.history.emplace_back(record);
        if (callbacks.iteration)
          callbacks.iteration(state.history.back());
        if (callbacks.checkpoint)
          callbacks.checkpoint(state);
        stopped = callbacks.interrupted && callbacks.interrupted();
        return !stopped;
      });
  if (result.converged) {
    // Recorded so that a run resumed after this point does not take more steps.
    state.forward_fit_converged = true;
    if (callbacks.checkpoint)
      callbacks.checkpoint(state);
    return true;
  }
  return !stopped || state.forward_fit_steps >= options.forward_fit.max_iterations;
}

/// Make the loop's iteration k the best, the forward fit's start (iteration 0: no correction).
/// Throws std::logic_error for an iteration that did not complete.
void start_forward_fit_from(int k, LearningState& state) {
  if (k == state.best_iteration)
    return;
  const auto record = std::find_if(state.history.begin(), state.history.end(),
      [&](const IterationRecord& r) { return iteration_of(r) == k; });
  const auto tried = state.tried.find(k); // the corrections simulated: none for the nominal
  if (record == state.history.end() || !forward_of(*record).completed()
      || (tried == state.tried.end() && k != 0))
    throw std::logic_error("the forward fit cannot start from iteration " + std::to_string(k)
        + ": it did not complete");
  state.best = tried == state.tried.end() ? nullptr : tried->second;
  state.best_error = forward_of(*record).error().rms;
  state.best_iteration = k;
}

} // namespace

bool run_learning(const sim::Scene& scene, const observe::Observation& observed,
    const LearningOptions& options, LearningState& state, const LearningCallbacks& callbacks) {
  const Motion motion { scene.name, scene, observed };
  return run_learning(std::span(&motion, 1), options, state, callbacks);
}

bool run_learning(std::span<const Motion> motions, const LearningOptions& options,
    LearningState& state, const LearningCallbacks& callbacks) {
  LoopSetup setup;
  set_up(motions, options, setup);
  auto interrupted = [&] { return callbacks.interrupted && callbacks.interrupted(); };
  while (!state.finished) {
    if (interrupted())
      return false;
    const int k = state.next_iteration;
    // 1. Forward simulation of every motion with C_k: the convergence signal.
    ForwardStage forward = simulate_motions(motions, state.correction, callbacks.progress);
    if (forward.diverged_motion >= 0 && k == 0)
      throw InputError(motion_field(motions, static_cast<size_t>(forward.diverged_motion), "scene"),
          "the nominal model's forward simulation failed: "
              + forward.runs[static_cast<size_t>(forward.diverged_motion)].message);
    LearningState next = after_forward(state, forward.outcome, options); // committed at the end
    LoopNext what_next = LoopEnd {};
    if (next.failed_steps_in_a_row > 0 && !next.finished) {
      // C_k overshot (a simulation diverged or, backtracking, it is no better than the best):
      // halve the step from the best correction and try that. Deterministic, so a resumed run
      // takes the same path.
      next.correction = halfway(state.correction, next.best);
      if (next.correction)
        what_next = DampedUpdate {};
      else
        next.finished = true;
    } else if (!next.finished) {
      // 2–6. The trajectory stages: C_{k+1}.
      auto stages
          = trajectory_stages(motions, setup, forward, state.correction, options, k, callbacks);
      if (!stages)
        return false;
      next.correction = std::move(stages->correction);
      what_next = stages->record;
    }
    next.next_iteration = k + 1;
    next.history.emplace_back(LoopRecord { k, std::move(forward.outcome), what_next });
    if (interrupted())
      return false;
    state = std::move(next);
    if (callbacks.iteration)
      callbacks.iteration(state.history.back());
    if (callbacks.checkpoint)
      callbacks.checkpoint(state);
  }
  if (options.forward_fit.max_iterations > 0 && state.forward_fit_steps == 0
      && callbacks.forward_fit_start)
    start_forward_fit_from(callbacks.forward_fit_start(state), state);
  return run_forward_fit(motions, setup.meshes, options, state, callbacks);
}

} // namespace elastolearn::learn
