#pragma once
/// \file The stages of the learning loop (learning_loop.hpp, paper 000 §3), each a function of
/// what it needs that returns what it gives. run_learning chains them and keeps the loop's
/// bookkeeping (best correction, patience, damped updates, checkpoints); nothing here changes
/// LearningState. Per iteration k, with C_k the current correction:
///   1. simulate_motions: forward simulation of every motion → ForwardStage;
///   2. constrained_simulation: observed vertices follow their data (Eqs. 6–8);
///   3. trajectory_basis: POD basis Φ (§5.1), and space_time_origin, where stage 4 starts;
///   4. optimize_space_time (space_time.hpp): sparse reduced space-time optimisation (Eqs. 2–4);
///   5. reconstruction_inputs: control forces (Eq. 5) → what the correction must produce;
///   6. reconstruct_correction: k-means centres, stress reconstruction over every motion
///      (Eqs. 10–13) and the stability shrink → C_{k+1}.
/// After the loop, forward_fit_start and forward_fit_record frame the forward fit's steps.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/forward_fit.hpp>
#include <elastolearn/learn/iteration_record.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/learn/pod_basis.hpp>
#include <elastolearn/learn/trajectory_physics.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <deque>
#include <memory>
#include <span>
#include <vector>

namespace elastolearn::learn {

/// What the loop precomputes once for one motion. Setups (and OptimizedMotion below) are built in
/// place in a std::deque, which never relocates its elements as it grows, so references to them
/// (and to their DofMaps, held by ReconstructionMotion) stay valid.
struct MotionSetup {
  explicit MotionSetup(const Motion& motion);
  std::vector<int> basis_vertices; ///< the free vertices
  /// The scene with the observed vertices following their data (lost entries filled by
  /// fill_lost_entries; a vertex never seen is not tracked).
  sim::Scene tracked_scene;
  /// Every free vertex observed (small meshes): the constrained trajectory is the data itself.
  bool all_free_tracked = false;
  TrajectoryPhysics nominal_physics; ///< the nominal model, for the control forces
};

/// Stage 1's result: every motion's forward simulation with one correction.
struct ForwardStage {
  /// One per motion, in order, up to the first that diverged (later ones are not simulated).
  std::vector<sim::ForwardRun> runs;
  /// Completed with the error over all motions' observations (combined_error), or diverged
  /// with the first failing run's message ("motion NAME: " before it when there are several).
  ForwardOutcome outcome;
  /// The motion whose simulation diverged (−1: none).
  int diverged_motion = -1;
};

/// Stage 1: simulate every motion's scene with `correction` (null = the nominal) and measure
/// the error at its observations; stops at the first motion that diverges.
ForwardStage simulate_motions(std::span<const Motion> motions,
    const std::shared_ptr<const material::RbfCorrection>& correction,
    const ProgressCallback& progress = {});

/// Stage 2: the constrained simulation of one motion with `correction` — the observed vertices
/// follow their data, the rest is simulated. With every free vertex observed it is `forward`
/// with the observed vertices moved to their data. A divergence is a result (completed false).
sim::ForwardRun constrained_simulation(const MotionSetup& setup, const sim::ForwardRun& forward,
    const std::shared_ptr<const material::RbfCorrection>& correction,
    const ProgressCallback& progress = {});

/// Stage 3: the basis Φ of one motion's space-time optimisation: POD of the forward simulation
/// and (options.pod_with_constrained, when it completed) of the constrained one, over the free
/// vertices; the identity on the free dofs for options.full_space.
PodBasis trajectory_basis(const sim::Scene& scene, const MotionSetup& setup,
    const sim::ForwardRun& forward, const sim::ForwardRun& constrained,
    const LearningOptions& options);

/// Where stage 4 starts: o_i = f_i + Φ Φᵀ (c_i − f_i), the forward trajectory f plus the
/// constrained one c projected onto span Φ (f itself if c diverged). The projection keeps the
/// start smooth: dragging a few observed vertices leaves sharp local dents (large point forces)
/// that no reduced step could remove and no material explains.
std::vector<VecX> space_time_origin(
    const sim::ForwardRun& forward, const sim::ForwardRun& constrained, const PodBasis& basis);

/// What stages 2–5 leave of one motion for the reconstruction.
struct OptimizedMotion {
  explicit OptimizedMotion(const sim::Scene& current)
      : physics(current) { }
  TrajectoryPhysics physics; ///< with the current correction (its DofMap)
  std::vector<VecX> trajectory; ///< the optimised frames 0..T (their stretches place the centres)
  std::vector<VecX> positions, velocities, targets; ///< frames 1..T, for the reconstruction
  MatX projection; ///< Φ on the free dofs (the projected reconstruction), or empty
};

/// Stage 5: from the optimised trajectory `optimized` (frames 0..T) of one motion, the targets of
/// the reconstruction — the nominal model's residual along it (the current correction's force
/// plus the control forces, Eq. 5) — with its positions and finite-difference velocities, frames
/// 1..T, into `out` (whose physics ran stage 4); `out.projection` is Φ on the free dofs when the
/// options ask for the projected reconstruction.
void reconstruction_inputs(MotionSetup& setup, std::vector<VecX> optimized,
    const VecX& initial_velocity, double dt, const PodBasis& basis, const LearningOptions& options,
    OptimizedMotion& out);

/// Stage 6's result: C_{k+1} and what the reconstruction measured.
struct Reconstruction {
  std::shared_ptr<const material::RbfCorrection> correction; ///< C_{k+1} (null: the nominal)
  int centres = 0; ///< RBF kernels
  double misfit = 0; ///< RMS force misfit against the targets [N]
  double target = 0; ///< RMS of the targets [N]
  double stability = 0; ///< min_relative_eigenvalue of the whole reconstructed correction
  double step_kept = 1; ///< the fraction of it kept to stay stable (0: none)
  Eigen::Index stability_cuts = 0; ///< conditions its fit was held to (stability_cuts.hpp)
};

/// Stage 6: centres by k-means over every motion's optimised stretches (seeded with `seed`), one
/// stress reconstruction whose equations are every motion's frames (with
/// options.stability_cuts, solved subject to stability cuts at the samples below), then the
/// largest fraction ½ᵏ (k ≤ 4) of the result that is stable where the trajectories go
/// (stretches, σ^1.25 and the reachable stretches; with the cuts, also
/// options.forward_fit.stability_stretches); none if no fraction is. `meshes[i]` is motion i's
/// reconstruction mesh.
Reconstruction reconstruct_correction(std::span<const ReconstructionMesh> meshes,
    const std::deque<OptimizedMotion>& motions, const fem::MaterialModel& nominal,
    const LearningOptions& options, const StressReconstructionOptions& reconstruction,
    std::uint64_t seed);

/// The reconstruction options of a run: options.reconstruction with the frame stride raised so
/// that the longest motion (`longest_frames`) uses at most options.max_reconstruction_frames.
StressReconstructionOptions reconstruction_options(
    const LearningOptions& options, int longest_frames);

/// Where the forward fit starts: its design (the best correction's centres, or k-means centres
/// of the nominal motions' stretches when nothing was learned), start unknowns and options (the
/// remaining steps, the saved μ, stability samples where the best correction's motions go).
struct ForwardFitStart {
  RbfDesign design;
  VecX start;
  ForwardFitOptions options;
};

/// Simulates every motion with `best` (whose runs completed before) to place the stability
/// samples (and the centres when `best` is null). `damping` is the saved μ (≤ 0: the options').
ForwardFitStart forward_fit_start(std::span<const Motion> motions,
    std::span<const ReconstructionMesh> meshes,
    const std::shared_ptr<const material::RbfCorrection>& best, const LearningOptions& options,
    int remaining_steps, double damping, const ProgressCallback& progress = {});

/// The record of one forward-fit trial, step `iteration` of the run.
ForwardFitRecord forward_fit_record(
    int iteration, const ForwardSensitivityPass& trial, bool accepted, const RbfDesign& design);

} // namespace elastolearn::learn
