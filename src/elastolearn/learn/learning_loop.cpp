#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/observe/observation_noise.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <string>

namespace elastolearn::learn {

namespace {

/// The scene with the observed (not already prescribed) vertices following their data. Lost
/// entries follow the smoothest continuation of their vertex's seen ones (fill_lost_entries);
/// a vertex never seen is not tracked.
sim::Scene constrained_scene(const sim::Scene& scene, const observe::Observation& given) {
  sim::Scene out = scene;
  const auto prescribed = scene.prescribed_vertices();
  auto tracked = std::make_shared<sim::TrackedVertices>();
  const observe::Observation observed = observe::fill_lost_entries(given);
  std::vector<int> rows;
  for (int j = 0; j < observed.num_observed(); ++j)
    if (!std::binary_search(prescribed.begin(), prescribed.end(), observed.vertex_ids[j])
        && (observed.valid.size() == 0 || observed.valid.col(j).maxCoeff() != 0)) {
      tracked->vertices.push_back(observed.vertex_ids[j]);
      rows.push_back(j);
    }
  if (tracked->vertices.empty())
    return out;
  tracked->dt = observed.dt;
  tracked->start_time = observed.start_time;
  tracked->positions.reserve(observed.positions.size());
  for (const auto& frame : observed.positions) {
    Positions p(static_cast<Eigen::Index>(rows.size()), 3);
    for (size_t i = 0; i < rows.size(); ++i)
      p.row(static_cast<Eigen::Index>(i)) = frame.row(rows[i]);
    tracked->positions.push_back(std::move(p));
  }
  out.tracked = std::move(tracked);
  return out;
}

std::vector<int> free_vertices(const sim::Scene& scene) {
  const auto prescribed = scene.prescribed_vertices();
  std::vector<int> out;
  for (int v = 0; v < scene.mesh.num_vertices(); ++v)
    if (!std::binary_search(prescribed.begin(), prescribed.end(), v))
      out.push_back(v);
  return out;
}

std::vector<Positions> as_positions(const std::vector<VecX>& frames) {
  std::vector<Positions> out;
  out.reserve(frames.size());
  for (const auto& x : frames)
    out.emplace_back(unflatten(x));
  return out;
}

/// `run` with the tracked vertices moved to their data at every frame.
sim::ForwardRun with_tracked_data(sim::ForwardRun run, const sim::Scene& tracked_scene) {
  if (!run.completed || !tracked_scene.tracked)
    return run;
  const auto& tracked = *tracked_scene.tracked;
  for (size_t i = 0; i < run.positions.size(); ++i)
    for (size_t j = 0; j < tracked.vertices.size(); ++j)
      run.positions[i].segment<3>(3 * tracked.vertices[j]) = tracked.position_at(
          static_cast<int>(j), tracked.start_time + static_cast<double>(i) * tracked.dt);
  return run;
}

/// The full-space variant: Φ = the identity on the free dofs (no reduction).
PodBasis identity_basis(int num_vertices, const std::vector<int>& free_vertices) {
  PodBasis basis;
  const auto columns = static_cast<Eigen::Index>(3 * free_vertices.size());
  basis.modes = MatX::Zero(3 * static_cast<Eigen::Index>(num_vertices), columns);
  for (size_t i = 0; i < free_vertices.size(); ++i)
    for (int c = 0; c < 3; ++c)
      basis.modes(3 * free_vertices[i] + c, static_cast<Eigen::Index>(3 * i + c)) = 1;
  basis.captured_energy = 1;
  return basis;
}

/// The last iteration's control-force RMS is below 95 % of every earlier one.
bool control_forces_still_shrinking(const std::vector<IterationRecord>& history) {
  if (history.size() < 2)
    return false;
  const double last = history.back().control_force_rms;
  for (size_t i = 0; i + 1 < history.size(); ++i)
    if (!(last < 0.95 * history[i].control_force_rms))
      return false;
  return last > 0;
}

template <typename T> std::vector<T> without_first(const std::vector<T>& v) {
  return { v.begin() + 1, v.end() };
}

} // namespace

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

/// What the loop precomputes once for one motion. Setups (and OptimizedMotion below) are built in
/// place in a std::deque, which never relocates its elements as it grows, so references to them
/// (and to their DofMaps, held by ReconstructionMotion) stay valid.
struct MotionSetup {
  explicit MotionSetup(const Motion& motion)
      : basis_vertices(free_vertices(motion.scene))
      , tracked_scene(constrained_scene(motion.scene, motion.observed))
      , nominal_physics(motion.scene) {
    // Every free vertex observed (small meshes): the constrained trajectory is the data itself.
    all_free_tracked
        = tracked_scene.tracked && tracked_scene.tracked->vertices.size() == basis_vertices.size();
  }
  std::vector<int> basis_vertices; ///< the free vertices
  sim::Scene tracked_scene; ///< the observed vertices follow their data
  bool all_free_tracked = false;
  TrajectoryPhysics nominal_physics;
};

/// The field name of motion i in messages: the single-motion name for one motion.
std::string motion_field(std::span<const Motion> motions, size_t i, const std::string& field) {
  return motions.size() == 1 ? field : "motions[" + std::to_string(i) + "]." + field;
}

/// √ of the weighted mean of two mean squares a², b² with weights wa, wb.
double merged_rms(double a, double wa, double b, double wb) {
  return std::sqrt((wa * a * a + wb * b * b) / (wa + wb));
}

/// Where the loop's corrections must be stable: the trajectory's stretches and σ^1.25 (a forward
/// simulation with a softening correction strains more than the trajectory it was fitted to, and
/// there the correction's tails extrapolate). Larger amplifications there made the turtle's first
/// correction unstable at a few samples beyond the training's extremes and halved every step;
/// the recipe's validation checks its candidates further out (learning_recipe.cpp).
constexpr std::array<double, 2> kLoopAmplifications { 1.0, 1.25 };

/// The principal stretches of every motion's trajectory, stacked (options.stretch_samples caps
/// each motion's samples): where the RBF centres go and where a correction must be stable.
MatX trajectory_stretches(std::span<const ReconstructionMesh> meshes,
    const std::vector<const std::vector<VecX>*>& trajectories, const LearningOptions& options) {
  std::vector<MatX> parts;
  parts.reserve(trajectories.size());
  Eigen::Index rows = 0;
  for (size_t i = 0; i < trajectories.size(); ++i) {
    parts.push_back(collect_stretches(meshes[i], *trajectories[i], options.stretch_samples));
    rows += parts.back().rows();
  }
  MatX stacked(rows, 3);
  rows = 0;
  for (const MatX& part : parts) {
    stacked.middleRows(rows, part.rows()) = part;
    rows += part.rows();
  }
  return stacked;
}

/// RBF centres: k-means over the stretch views of `stretches` (at most options.centres).
MatX rbf_centres(const MatX& stretches, const LearningOptions& options, std::uint64_t seed) {
  const MatX views = stretch_views(stretches);
  KMeansOptions kmeans_options;
  kmeans_options.clusters = std::min<int>(options.centres, static_cast<int>(views.rows()));
  kmeans_options.seed = seed;
  return kmeans(views, kmeans_options).centres;
}

/// The reconstructed correction, or the largest fraction ½ᵏ (k ≤ 4) of it whose material is
/// stable at every stability sample (material_stability); none (the nominal) if no fraction is.
/// A correction is reconstructed whole on the nominal (not as a step from the last one), so
/// shrinking it moves towards the nominal, which is stable, and keeps its centres. A
/// reconstruction from noisy or sparse data can remove more stiffness than the nominal has
/// somewhere; its simulations then diverge, which no later halving of the step repairs as
/// cheaply as this check.
std::shared_ptr<const material::RbfCorrection> stable_fraction(
    const material::RbfCorrection& fitted, const fem::MaterialModel& nominal, const MatX& stretches,
    IterationRecord& record) {
  double kept = 1;
  for (int k = 0; k <= 4; ++k, kept *= 0.5) {
    auto shrunk = std::make_shared<material::RbfCorrection>(
        k == 0 ? fitted : material::blend(fitted, nullptr, 1 - kept));
    const StabilityReport stability = material_stability(*nominal.elastic, shrunk.get(), stretches);
    if (k == 0)
      record.stability = stability.min_relative_eigenvalue;
    if (stability.stable()) {
      record.step_kept = kept;
      return shrunk;
    }
  }
  record.step_kept = 0;
  return nullptr;
}

/// The stage after the loop: Levenberg–Marquardt on the forward error summed over the motions
/// from the best correction (LearningOptions::forward_fit). Each step is one IterationRecord and
/// one checkpoint; a resumed run restarts from the best correction with the saved μ, so it takes
/// the same steps.
bool run_forward_fit(std::span<const Motion> motions, std::span<const ReconstructionMesh> meshes,
    const LearningOptions& options, LearningState& state, const LearningCallbacks& callbacks) {
  const int remaining = options.forward_fit.max_iterations - state.forward_fit_steps;
  if (remaining <= 0)
    return true;
  if (callbacks.interrupted && callbacks.interrupted())
    return false;
  // Centres: the best correction's, or (nothing learned) k-means over the nominal motions'
  // stretches. Trials must be stable where the best correction's motions go (and beyond).
  std::vector<std::vector<VecX>> best_runs;
  std::vector<const std::vector<VecX>*> trajectories;
  best_runs.reserve(motions.size());
  for (const Motion& motion : motions) {
    best_runs.push_back(
        sim::simulate_positions(sim::with_correction(motion.scene, state.best), callbacks.progress)
            .positions); // the best correction's runs completed before: never empty
    trajectories.push_back(&best_runs.back());
  }
  const MatX stretches = trajectory_stretches(meshes, trajectories, options);
  const MatX centres = state.best ? MatX(state.best->parameters().centres)
                                  : rbf_centres(stretches, options, options.seed);
  const RbfDesign design(centres, options.rbf);
  const VecX start
      = state.best ? design.unknowns(*state.best) : VecX(VecX::Zero(design.num_unknowns()));
  ForwardFitOptions fit_options = options.forward_fit;
  fit_options.max_iterations = remaining;
  if (state.forward_fit_damping > 0)
    fit_options.damping = state.forward_fit_damping;
  if (stretches.rows() > 0)
    fit_options.stability_stretches = amplified_stretches(stretches, kLoopAmplifications, 30000);
  bool stopped = false;
  fit_to_observations(motions, meshes, design, start, fit_options, callbacks.progress,
      [&](const ForwardSensitivityPass& trial, bool accepted, const VecX& kept, double damping) {
        IterationRecord record;
        record.iteration = state.next_iteration;
        record.forward_fit = true;
        record.forward_fit_accepted = accepted;
        record.forward_completed = trial.completed;
        record.forward_message = trial.message;
        record.forward_unstable = trial.unstable;
        if (trial.completed)
          record.forward_error = trial.error;
        record.centres = design.num_centres();
        record.seconds_forward = trial.seconds;
        // The kept unknowns are the best correction (the start's, until a step is accepted).
        state.correction = std::make_shared<material::RbfCorrection>(design.correction(kept));
        if (accepted) {
          state.best = state.correction;
          state.best_error = trial.error.rms;
          state.best_iteration = record.iteration;
        }
        ++state.forward_fit_steps;
        state.forward_fit_damping = damping;
        state.next_iteration = record.iteration + 1;
        state.history.push_back(record);
        if (callbacks.iteration)
          callbacks.iteration(record);
        if (callbacks.checkpoint)
          callbacks.checkpoint(state);
        stopped = callbacks.interrupted && callbacks.interrupted();
        return !stopped;
      });
  return !stopped || state.forward_fit_steps >= options.forward_fit.max_iterations;
}

/// What stages 2–4 leave of one motion for the reconstruction.
struct OptimizedMotion {
  explicit OptimizedMotion(const sim::Scene& current)
      : physics(current) { }
  TrajectoryPhysics physics; ///< with the current correction (its DofMap)
  std::vector<VecX> trajectory; ///< the optimised frames 0..T (their stretches place the centres)
  std::vector<VecX> positions, velocities, targets; ///< frames 1..T, for the reconstruction
  MatX projection; ///< Φ on the free dofs, or empty
};

} // namespace

bool run_learning(const sim::Scene& scene, const observe::Observation& observed,
    const LearningOptions& options, LearningState& state, const LearningCallbacks& callbacks) {
  const Motion motion { scene.name, scene, observed };
  return run_learning(std::span(&motion, 1), options, state, callbacks);
}

bool run_learning(std::span<const Motion> motions, const LearningOptions& options,
    LearningState& state, const LearningCallbacks& callbacks) {
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
  }
  auto interrupted = [&] { return callbacks.interrupted && callbacks.interrupted(); };

  // The learned Δα₁ may lower the nominal damping; fem::ElasticForce keeps α₁ + Δα₁ ≥ 0.
  const RbfFitOptions& rbf = options.rbf;
  std::vector<ReconstructionMesh> meshes;
  std::deque<MotionSetup> setups;
  meshes.reserve(motions.size());
  int longest = 0; // frames of the longest motion
  for (size_t i = 0; i < motions.size(); ++i) {
    const sim::Scene& scene = motions[i].scene;
    meshes.emplace_back(scene.mesh, scene.material);
    const MotionSetup& setup = setups.emplace_back(motions[i]);
    if (options.full_space
        && 3 * static_cast<long>(setup.basis_vertices.size()) > options.max_full_space_dofs)
      throw InputError(motion_field(motions, i, "learn.full_space"),
          "the full-space variant solves dense " + std::to_string(3 * setup.basis_vertices.size())
              + "² blocks per frame; it is meant for meshes up to "
              + std::to_string(options.max_full_space_dofs)
              + " free dofs: use the reduced (POD) variant");
    longest = std::max(longest, scene.frames);
  }
  StressReconstructionOptions reconstruction_options = options.reconstruction;
  if (options.max_reconstruction_frames > 0)
    reconstruction_options.frame_stride = std::max(reconstruction_options.frame_stride,
        (longest + options.max_reconstruction_frames - 1) / options.max_reconstruction_frames);

  std::vector<sim::ForwardRun> forwards(motions.size());
  std::vector<ErrorSummary> errors(motions.size());
  while (!state.finished) {
    if (interrupted())
      return false;
    IterationRecord record;
    record.iteration = state.next_iteration;
    LearningState next = state; // committed only once the iteration is complete

    // 1. Forward simulation of every motion with C_k: the convergence signal (their RMS error
    // over all observations). The iteration diverged if one of them did.
    auto t0 = Clock::now();
    bool completed = true;
    for (size_t i = 0; i < motions.size() && completed; ++i) {
      forwards[i] = sim::simulate_positions(
          sim::with_correction(motions[i].scene, state.correction), callbacks.progress);
      completed = forwards[i].completed;
      if (!completed && record.iteration == 0)
        throw InputError(motion_field(motions, i, "scene"),
            "the nominal model's forward simulation failed: " + forwards[i].message);
      if (completed)
        errors[i] = observation_error(forwards[i].positions, motions[i].observed);
    }
    record.seconds_forward = seconds_since(t0);
    record.forward_completed = completed;
    for (size_t i = 0; i < motions.size(); ++i)
      if (!forwards[i].completed && record.forward_message.empty())
        record.forward_message
            = (motions.size() > 1 ? "motion " + motions[i].name + ": " : std::string())
            + forwards[i].message;
    if (completed)
      record.forward_error = combined_error(errors);
    const double error
        = completed ? record.forward_error.rms : std::numeric_limits<double>::infinity();
    // Progress is a better forward error, or (paper §3) control forces that still shrink clearly
    // although the forward error does not show it yet; the best correction is chosen by the former.
    const bool better_forward = completed && (next.best_error < 0 || error < next.best_error);
    if (better_forward) {
      next.best = state.correction;
      next.best_error = error;
      next.best_iteration = record.iteration;
    }
    next.divergences_in_a_row = completed ? 0 : state.divergences_in_a_row + 1;
    if (better_forward || (completed && control_forces_still_shrinking(state.history)))
      next.iterations_without_improvement = 0;
    else if (next.divergences_in_a_row == 0 || next.divergences_in_a_row > options.free_halvings)
      ++next.iterations_without_improvement;
    if (next.iterations_without_improvement >= options.patience
        || record.iteration >= options.max_iterations)
      next.finished = true;
    if (!completed && !next.finished) {
      // C_k overshot (a simulation diverged): halve the step from the best correction and try
      // that. Deterministic, so a resumed run takes the same path.
      next.correction = std::make_shared<material::RbfCorrection>(
          material::blend(*state.correction, next.best.get(), 0.5));
      record.damped_update = true;
    } else if (!next.finished) {
      // Stages 2–4 per motion, each with its own mesh and basis; records sum over motions
      // (control_force_rms is the RMS over all motions' steps and free dofs).
      std::deque<OptimizedMotion> optimized_motions;
      double control_weight = 0;
      for (size_t i = 0; i < motions.size(); ++i) {
        const sim::Scene& scene = motions[i].scene;
        MotionSetup& setup = setups[i];
        const sim::ForwardRun& forward = forwards[i];
        if (interrupted())
          return false;
        // 2. Constrained forward simulation: the starting trajectory (falls back to the forward
        // one).
        t0 = Clock::now();
        const sim::ForwardRun constrained = setup.all_free_tracked
            ? with_tracked_data(forward, setup.tracked_scene)
            : sim::simulate_positions(
                sim::with_correction(setup.tracked_scene, state.correction), callbacks.progress);
        record.seconds_constrained += seconds_since(t0);

        // 3. POD basis of the forward simulation (and of the constrained one).
        t0 = Clock::now();
        std::vector<std::vector<Positions>> snapshots { as_positions(forward.positions) };
        if (options.pod_with_constrained && constrained.completed)
          snapshots.push_back(as_positions(constrained.positions));
        const PodBasis basis = options.full_space
            ? identity_basis(scene.mesh.num_vertices(), setup.basis_vertices)
            : pod_basis(std::span<const std::vector<Positions>>(snapshots),
                scene.mesh.rest_positions(), setup.basis_vertices, options.pod);
        record.modes += basis.num_modes();
        record.seconds_pod += seconds_since(t0);
        t0 = Clock::now();
        // The optimisation moves the forward trajectory within span Φ (x_i = forward_i + Φ z_i),
        // starting from the constrained simulation projected onto that span. The projection
        // keeps the start smooth: dragging a few observed vertices leaves sharp local dents
        // (large point forces) that no reduced step could remove and no material explains.
        std::vector<VecX> origin = forward.positions;
        if (constrained.completed)
          for (size_t f = 0; f < origin.size(); ++f)
            origin[f].noalias() += basis.modes
                * (basis.modes.transpose() * (constrained.positions[f] - forward.positions[f]));
        record.seconds_constrained += seconds_since(t0);
        if (interrupted())
          return false;

        // 4. Sparse reduced space-time optimisation.
        t0 = Clock::now();
        OptimizedMotion& out
            = optimized_motions.emplace_back(sim::with_correction(scene, state.correction));
        SpaceTimeResult optimized = optimize_space_time(out.physics, basis.modes, origin,
            forward.initial_velocity, motions[i].observed, options.space_time, callbacks.progress);
        record.space_time_initial += optimized.initial_objective;
        record.space_time_objective += optimized.objective;
        record.space_time_iterations += optimized.iterations;
        const double weight
            = double(scene.frames) * double(out.physics.dofs().num_free()); // steps × free dofs
        record.control_force_rms = i == 0
            ? optimized.physics_rms
            : merged_rms(record.control_force_rms, control_weight, optimized.physics_rms, weight);
        control_weight += weight;
        record.seconds_space_time += seconds_since(t0);

        // 5. Control forces → the total force the correction must produce (nominal residual).
        t0 = Clock::now();
        const auto targets = trajectory_residuals(
            setup.nominal_physics, optimized.positions, forward.initial_velocity);
        const auto velocities
            = finite_difference_velocities(optimized.positions, forward.initial_velocity, scene.dt);
        out.positions = without_first(optimized.positions);
        out.velocities = without_first(velocities);
        out.targets = without_first(targets);
        out.trajectory = std::move(optimized.positions);
        if (options.projected_reconstruction && !options.full_space
            && options.reconstruction.method == ReconstructionMethod::normal_equations)
          out.projection = basis.modes(out.physics.dofs().free_dofs(), Eigen::all);
        record.seconds_reconstruction += seconds_since(t0);
      }
      if (interrupted())
        return false;

      // 5–6. Centres by k-means over all motions' optimised stretches, then one stress
      // reconstruction whose equations are every motion's frames.
      t0 = Clock::now();
      std::vector<const std::vector<VecX>*> trajectories;
      std::vector<ReconstructionMotion> blocks;
      blocks.reserve(motions.size());
      for (size_t i = 0; i < motions.size(); ++i) {
        const OptimizedMotion& m = optimized_motions[i];
        trajectories.push_back(&m.trajectory);
        blocks.push_back(
            { meshes[i], m.physics.dofs(), m.positions, m.velocities, m.targets, m.projection });
      }
      const MatX stretches = trajectory_stretches(meshes, trajectories, options);
      const RbfDesign design(rbf_centres(stretches, options,
                                 options.seed + static_cast<std::uint64_t>(record.iteration)),
          rbf);
      const StressReconstructionResult reconstructed
          = reconstruct_rbf_correction(blocks, design, reconstruction_options);
      record.centres = design.num_centres();
      record.correction_misfit = reconstructed.misfit.rms_residual;
      record.correction_target = reconstructed.misfit.rms_target;
      next.correction = stable_fraction(reconstructed.correction, motions.front().scene.material,
          amplified_stretches(stretches, kLoopAmplifications, 30000), record);
      record.seconds_reconstruction += seconds_since(t0);
    }
    next.next_iteration = record.iteration + 1;
    next.history.push_back(record);
    if (interrupted())
      return false;
    state = std::move(next);
    if (callbacks.iteration)
      callbacks.iteration(record);
    if (callbacks.checkpoint)
      callbacks.checkpoint(state);
  }
  return run_forward_fit(motions, meshes, options, state, callbacks);
}

} // namespace elastolearn::learn
