#include <elastolearn/core/stacked_rows.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/kmeans.hpp>
#include <elastolearn/learn/learning_stages.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/learn/space_time.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>
#include <elastolearn/observe/observation_noise.hpp>

#include <algorithm>
#include <array>
#include <limits>
#include <string>

namespace elastolearn::learn {

namespace {

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

template <typename T> std::vector<T> without_first(const std::vector<T>& v) {
  return { v.begin() + 1, v.end() };
}

/// Where the loop's corrections must be stable: the trajectory's stretches and σ^1.25 (a forward
/// simulation with a softening correction strains more than the trajectory it was fitted to, and
/// there the correction's tails extrapolate). Larger amplifications there made the turtle's first
/// correction unstable at a few samples beyond the training's extremes and halved every step;
/// the recipe's validation checks its candidates further out (learning_recipe.cpp).
constexpr std::array<double, 2> kLoopAmplifications { 1.0, 1.25 };

/// Every stability sample of the loop and the forward fit: the trajectory's stretches amplified
/// (kLoopAmplifications) and the stretches a motion of another kind may reach
/// (learn::reachable_stretches with the recipe's bounds).
MatX stability_samples(const material::ElasticModel& nominal, const MatX& stretches) {
  return stacked_rows(
      std::vector<MatX> { amplified_stretches(stretches, kLoopAmplifications, 30000),
          reachable_stretches(nominal, stretches) },
      3);
}

/// The principal stretches of every motion's trajectory, stacked (options.stretch_samples caps
/// each motion's samples): where the RBF centres go and where a correction must be stable.
MatX trajectory_stretches(std::span<const ReconstructionMesh> meshes,
    const std::vector<const std::vector<VecX>*>& trajectories, const LearningOptions& options) {
  std::vector<MatX> parts;
  parts.reserve(trajectories.size());
  for (size_t i = 0; i < trajectories.size(); ++i)
    parts.push_back(collect_stretches(meshes[i], *trajectories[i], options.stretch_samples));
  return stacked_rows(parts, 3);
}

/// The corrections' trusted stretches (material/trusted_stretches.hpp): the interval of every
/// principal stretch of `stretches`, the trajectories a correction is learned from. With energy
/// kernels a correction is continued beyond it as rbf.continuation says, either keeping at least
/// half of the nominal's rest stiffness in every direction (bounded_softening) or half of its
/// shear stiffness along a stretch beyond (smooth_clamp); stress kernels are not continued.
material::TrustedStretches trusted_interval(
    const MatX& stretches, const RbfFitOptions& rbf, const material::ElasticModel& nominal) {
  if (!rbf.energy_kernels || stretches.size() == 0)
    return {};
  material::TrustedStretches trusted { stretches.minCoeff(), stretches.maxCoeff() };
  trusted.continuation = rbf.continuation;
  trusted.nominal_stiffness = nominal.principal_stress_derivative(Vec3::Ones());
  return trusted;
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
/// cheaply as this check. Sets out.correction, out.stability and out.step_kept.
void stable_fraction(const material::RbfCorrection& fitted, const fem::MaterialModel& nominal,
    const MatX& stretches, Reconstruction& out) {
  double kept = 1;
  for (int k = 0; k <= 4; ++k, kept *= 0.5) {
    auto shrunk = std::make_shared<material::RbfCorrection>(
        k == 0 ? fitted : material::blend(fitted, nullptr, 1 - kept));
    const StabilityReport stability = material_stability(*nominal.elastic, shrunk.get(), stretches);
    if (k == 0)
      out.stability = stability.min_relative_eigenvalue;
    if (stability.stable()) {
      out.step_kept = kept;
      out.correction = std::move(shrunk);
      return;
    }
  }
  out.step_kept = 0;
  out.correction = nullptr;
}

} // namespace

MotionSetup::MotionSetup(const Motion& motion)
    : basis_vertices(free_vertices(motion.scene))
    , tracked_scene(constrained_scene(motion.scene, motion.followed()))
    , nominal_physics(motion.scene) {
  all_free_tracked
      = tracked_scene.tracked && tracked_scene.tracked->vertices.size() == basis_vertices.size();
}

ForwardStage simulate_motions(std::span<const Motion> motions,
    const std::shared_ptr<const material::RbfCorrection>& correction,
    const ProgressCallback& progress) {
  const auto t0 = Clock::now();
  std::vector<sim::ForwardRun> runs;
  std::vector<ErrorSummary> errors;
  runs.reserve(motions.size());
  errors.reserve(motions.size());
  for (const Motion& motion : motions) {
    runs.push_back(
        sim::simulate_positions(sim::with_correction(motion.scene, correction), progress));
    if (!runs.back().completed) {
      const int i = static_cast<int>(runs.size()) - 1;
      std::string message = (motions.size() > 1 ? "motion " + motion.name + ": " : std::string())
          + runs.back().message;
      return { std::move(runs), ForwardOutcome::diverged(std::move(message), seconds_since(t0)),
        i };
    }
    errors.push_back(observation_error(runs.back().positions, motion.observed));
  }
  return { std::move(runs), ForwardOutcome::completed(combined_error(errors), seconds_since(t0)),
    -1 };
}

sim::ForwardRun constrained_simulation(const MotionSetup& setup, const sim::ForwardRun& forward,
    const std::shared_ptr<const material::RbfCorrection>& correction,
    const ProgressCallback& progress) {
  return setup.all_free_tracked
      ? with_tracked_data(forward, setup.tracked_scene)
      : sim::simulate_positions(sim::with_correction(setup.tracked_scene, correction), progress);
}

PodBasis trajectory_basis(const sim::Scene& scene, const MotionSetup& setup,
    const sim::ForwardRun& forward, const sim::ForwardRun& constrained,
    const LearningOptions& options) {
  if (options.full_space)
    return identity_basis(scene.mesh.num_vertices(), setup.basis_vertices);
  std::vector<std::vector<Positions>> snapshots { as_positions(forward.positions) };
  if (options.pod_with_constrained && constrained.completed)
    snapshots.push_back(as_positions(constrained.positions));
  return pod_basis(std::span<const std::vector<Positions>>(snapshots), scene.mesh.rest_positions(),
      setup.basis_vertices, options.pod);
}

std::vector<VecX> space_time_origin(
    const sim::ForwardRun& forward, const sim::ForwardRun& constrained, const PodBasis& basis) {
  std::vector<VecX> origin = forward.positions;
  if (constrained.completed)
    for (size_t f = 0; f < origin.size(); ++f)
      origin[f].noalias() += basis.modes
          * (basis.modes.transpose() * (constrained.positions[f] - forward.positions[f]));
  return origin;
}

void reconstruction_inputs(MotionSetup& setup, std::vector<VecX> optimized,
    const VecX& initial_velocity, double dt, const PodBasis& basis, const LearningOptions& options,
    OptimizedMotion& out) {
  const auto targets = trajectory_residuals(setup.nominal_physics, optimized, initial_velocity);
  const auto velocities = finite_difference_velocities(optimized, initial_velocity, dt);
  out.positions = without_first(optimized);
  out.velocities = without_first(velocities);
  out.targets = without_first(targets);
  out.trajectory = std::move(optimized);
  if (options.projected_reconstruction && !options.full_space
      && options.reconstruction.method == ReconstructionMethod::normal_equations)
    out.projection = basis.modes(out.physics.dofs().free_dofs(), Eigen::all);
}

Reconstruction reconstruct_correction(std::span<const ReconstructionMesh> meshes,
    const std::deque<OptimizedMotion>& motions, const fem::MaterialModel& nominal,
    const LearningOptions& options, const StressReconstructionOptions& reconstruction,
    std::uint64_t seed) {
  std::vector<const std::vector<VecX>*> trajectories;
  std::vector<ReconstructionMotion> blocks;
  blocks.reserve(motions.size());
  for (size_t i = 0; i < motions.size(); ++i) {
    const OptimizedMotion& m = motions[i];
    trajectories.push_back(&m.trajectory);
    blocks.push_back(
        { meshes[i], m.physics.dofs(), m.positions, m.velocities, m.targets, m.projection });
  }
  const MatX stretches = trajectory_stretches(meshes, trajectories, options);
  const RbfDesign design(rbf_centres(stretches, options, seed), options.rbf,
      trusted_interval(stretches, options.rbf, *nominal.elastic));
  std::vector<MatX> parts { stability_samples(*nominal.elastic, stretches) };
  if (options.stability_cuts && options.forward_fit.stability_stretches.rows() > 0)
    parts.push_back(options.forward_fit.stability_stretches);
  const MatX samples = stacked_rows(parts, 3);
  const StabilityRequirement requirement { *nominal.elastic, samples };
  const StressReconstructionResult reconstructed
      = reconstruct_rbf_correction(blocks, design, reconstruction,
          options.stability_cuts && reconstruction.method == ReconstructionMethod::normal_equations
              ? &requirement
              : nullptr);
  Reconstruction out;
  out.centres = design.num_centres();
  out.misfit = reconstructed.misfit.rms_residual;
  out.target = reconstructed.misfit.rms_target;
  out.stability_cuts = reconstructed.stability_cuts;
  stable_fraction(reconstructed.correction, nominal, samples, out);
  return out;
}

StressReconstructionOptions reconstruction_options(
    const LearningOptions& options, int longest_frames) {
  StressReconstructionOptions out = options.reconstruction;
  if (options.max_reconstruction_frames > 0)
    out.frame_stride = std::max(out.frame_stride,
        (longest_frames + options.max_reconstruction_frames - 1)
            / options.max_reconstruction_frames);
  return out;
}

ForwardFitStart forward_fit_start(std::span<const Motion> motions,
    std::span<const ReconstructionMesh> meshes,
    const std::shared_ptr<const material::RbfCorrection>& best, const LearningOptions& options,
    int remaining_steps, double damping, const ProgressCallback& progress) {
  std::vector<std::vector<VecX>> best_runs;
  std::vector<const std::vector<VecX>*> trajectories;
  best_runs.reserve(motions.size());
  for (const Motion& motion : motions) {
    best_runs.push_back(sim::simulate_positions(sim::with_correction(motion.scene, best), progress)
                            .positions); // the best correction's runs completed before
    trajectories.push_back(&best_runs.back());
  }
  const MatX stretches = trajectory_stretches(meshes, trajectories, options);
  const MatX centres
      = best ? MatX(best->parameters().centres) : rbf_centres(stretches, options, options.seed);
  // The best correction's own trusted interval, so that the design expresses it exactly.
  RbfDesign design(centres, options.rbf,
      best ? best->parameters().trusted
           : trusted_interval(stretches, options.rbf, *meshes.front().nominal.elastic));
  VecX start = best ? design.unknowns(*best) : VecX(VecX::Zero(design.num_unknowns()));
  ForwardFitOptions fit_options = options.forward_fit;
  fit_options.max_iterations = remaining_steps;
  if (damping > 0)
    fit_options.damping = damping;
  // The best correction's own runs' samples, and the caller's (the recipe's: where its
  // validation requires stability), which stay required.
  std::vector<MatX> samples;
  if (stretches.rows() > 0)
    samples.push_back(stability_samples(*motions.front().scene.material.elastic, stretches));
  if (options.forward_fit.stability_stretches.rows() > 0)
    samples.push_back(options.forward_fit.stability_stretches);
  fit_options.stability_stretches = stacked_rows(samples, 3);
  return { std::move(design), std::move(start), std::move(fit_options) };
}

ForwardFitRecord forward_fit_record(
    int iteration, const ForwardSensitivityPass& trial, bool accepted, const RbfDesign& design) {
  const ForwardOutcome forward = trial.completed
      ? ForwardOutcome::completed(trial.error, trial.seconds)
      : trial.unstable ? ForwardOutcome::unstable(trial.message, trial.seconds)
                       : ForwardOutcome::diverged(trial.message, trial.seconds);
  return { iteration, forward, accepted, design.num_centres() };
}

} // namespace elastolearn::learn
