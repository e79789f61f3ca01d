#pragma once
/// \file The learning loop of paper 000 (§3, Fig. 2; DESIGN.md "The learning loop"): from
/// observed vertex trajectories, learn an RBF correction N(F̂, Ḟ̂) of a nominal material so that
/// forward simulation reproduces the observations. Each iteration k:
///   1. forward-simulate with the current correction C_k; its error against the observations is
///      the convergence signal (the best C_k so far is kept);
///   2. constrained forward simulation: observed vertices follow their data (Eqs. 6–8);
///   3. POD basis Φ of both simulations (§5.1; the paper's uses the forward one only);
///   4. sparse reduced space-time optimisation from it (Eqs. 2–4, space_time.hpp);
///   5. control forces (Eq. 5) and stress reconstruction (Eqs. 10–13): the new correction's
///      nodal forces must equal the nominal model's residual along the optimised trajectory;
///   6. RBF centres re-clustered (k-means) over the trajectory's stretches each iteration.
/// The loop stops when neither the forward error nor the control forces (by 5 %) improved for
/// `patience` iterations, or after `max_iterations` corrections. A correction whose forward
/// simulation diverges is replaced by ½ (C_k + best) (a damped update, no trajectory stages);
/// the first `free_halvings` divergences in a row do not count against patience, later ones do.
/// Each iteration is one LoopRecord in LearningState::history, each forward-fit step one
/// ForwardFitRecord (iteration_record.hpp); the stages are learning_stages.hpp's functions.
/// Every stage is deterministic, and an iteration depends only on the current correction (and
/// the counters in LearningState), so a run resumed from a checkpoint reaches the same result.
/// Lost observation entries (Observation::valid) are ignored by every error and position term;
/// in stage 2 they follow the smoothest continuation of the seen ones (fill_lost_entries), so
/// no result depends on a lost entry's stored position.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/forward_fit.hpp>
#include <elastolearn/learn/iteration_record.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/learn/pod_basis.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/learn/space_time.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace elastolearn::learn {

struct LearningOptions {
  int max_iterations = 8; ///< corrections computed at most
  int patience = 2; ///< stop after this many iterations without a better forward error
  /// Divergences in a row that are halved towards the best correction without counting against
  /// patience: a step that overshoots is shortened to ½, ¼, … of itself before the loop gives up
  /// on its direction, because a correction whose whole and half steps diverge can still learn
  /// at a quarter (on the full-size sphere-tension case: docs/design_notes.md). Each halving
  /// still counts as an iteration.
  int free_halvings = 2;
  /// A correction whose forward error is not below the best one's is treated as one that
  /// diverged: halved towards the best (a damped update, no trajectory stages), so the loop
  /// only ever starts its stages from its best correction. Without it (paper §3) a worse
  /// correction still counts as progress while its control forces shrink, and the next stages
  /// start from it; the reconstruction's first whole step typically raises the forward error
  /// (docs/benchmarks_learning.md, "What limits the results").
  bool backtrack = false;
  PodOptions pod; ///< reduced basis (max_modes, frame window and stride)
  /// POD snapshots from the constrained simulation too, not only the forward one, so that span Φ
  /// contains the observed shapes the current model does not reach (docs/learning_loop.md: a
  /// sub-millimetre shape error outside span Φ leaves residual forces no material explains).
  bool pod_with_constrained = true;
  /// The full-space variant: no reduction, Φ = identity on the free dofs (small meshes only:
  /// each Gauss–Newton step factors T dense blocks of that size).
  bool full_space = false;
  int max_full_space_dofs = 1500; ///< refuse the full-space variant above this many free dofs
  SpaceTimeOptions space_time;
  int centres = 40; ///< RBF kernels m (k-means clusters)
  RbfFitOptions rbf; ///< ε, polynomial tails, damping part, regularisation
  StressReconstructionOptions reconstruction;
  /// Fit the correction's nodal forces to the control forces mainly within span Φ (the POD basis),
  /// where the reduced space-time optimisation controls the residual, instead of at every free
  /// dof (reconstruction.full_space_weight weighs the rest). The residual outside span Φ is
  /// left by the reduced trajectory's small strain errors, which grow as the mesh is refined,
  /// and fitting it makes the first correction overshoot (docs/learning.md, "Projected
  /// reconstruction"). Not used by the full-space variant (there span Φ is everything) nor by
  /// the lsqr reconstruction method.
  bool projected_reconstruction = true;
  /// Solve each reconstruction subject to stability cuts (stability_cuts.hpp) at its stability
  /// samples and at forward_fit.stability_stretches (where the recipe's validation requires
  /// stability), instead of only shrinking an unstable result (the shrinking stays as the
  /// fallback): a correction fitted on one kind of motion is otherwise free to soften states
  /// between its data, and shrinking it gives up its fit everywhere for them. The recipe's
  /// (RecipeOptions); off by default, as before the cuts.
  bool stability_cuts = false;
  /// Use at most this many frames of each motion in the reconstruction (a larger frame stride,
  /// the same for every motion, when the longest has more; 0 = all). Consecutive frames are
  /// nearly the same equations: 150 keep the fit's information at a fraction of the cost on
  /// long, finely stepped runs.
  int max_reconstruction_frames = 150;
  /// Samples for k-means, per motion; capped so that clustering stays cheap on big meshes and
  /// long runs.
  StretchSampleOptions stretch_samples = { 1, 100000 };
  std::uint64_t seed = 1; ///< k-means seeding
  /// After the loop: Levenberg–Marquardt steps on the forward simulation's error itself, from
  /// the best correction over its centres (forward_fit.hpp; 0 = none). The space-time stages
  /// hold the unobserved interior at the current model's equilibrium; this stage moves it with
  /// the corrected material: on the full-size sphere cases a few steps from the nominal model
  /// fit far better than the loop's iterations (docs/learning_loop.md; docs/learning.md,
  /// "Forward fit").
  ForwardFitOptions forward_fit;
  /// Throws InputError("learn.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// Everything needed to continue a run: the checkpoint.
struct LearningState {
  int next_iteration = 0; ///< k of the next forward simulation
  std::shared_ptr<const material::RbfCorrection> correction; ///< C_k (null = nominal)
  std::shared_ptr<const material::RbfCorrection> best; ///< best so far (null = nominal)
  double best_error = -1; ///< its RMS forward error [m] (−1: none yet)
  int best_iteration = -1;
  int iterations_without_improvement = 0;
  /// Steps that failed in a row: their forward simulation diverged, or (with
  /// LearningOptions::backtrack) its error was not below the best one's.
  int failed_steps_in_a_row = 0;
  bool finished = false; ///< the loop (its space-time iterations) ended
  int forward_fit_steps = 0; ///< forward-fit steps taken after it
  double forward_fit_damping = -1; ///< its current μ (−1: not started)
  bool forward_fit_converged = false; ///< it stopped at ForwardFitOptions::function_tolerance
  /// Every step so far, in order: the loop's iterations (LoopRecord), then the forward fit's
  /// steps (ForwardFitRecord).
  std::vector<IterationRecord> history;
  /// The correction each completed step simulated, by iteration: the loop's C_k (none for the
  /// nominal) and every accepted forward-fit step's. The recipe validates some of them, so a
  /// checkpoint keeps them all and a resumed run chooses among the same candidates.
  std::map<int, std::shared_ptr<const material::RbfCorrection>> tried;
};

struct LearningCallbacks {
  ProgressCallback progress; ///< within long stages
  /// After each step, a loop iteration or a forward-fit step (log a line).
  std::function<void(const IterationRecord&)> iteration;
  std::function<void(const LearningState&)> checkpoint; ///< after each iteration (save)
  std::function<bool()> interrupted; ///< polled between stages
  /// Called once the loop has ended and before the forward fit's first step: the iteration whose
  /// correction the forward fit starts from, the loop's best (state.best_iteration) or any earlier
  /// one that completed (0: no correction). Unset: the best.
  std::function<int(const LearningState&)> forward_fit_start;
};

/// Run (or continue, from `state`) the loop on `motions` (a training set, at least one): each
/// scene is the nominal model (its material must not carry a correction; every motion has the
/// same nominal material, their meshes, boundary conditions and lengths may differ) with its
/// observations (T + 1 frames = scene.frames + 1, same dt). One correction is learned from all:
/// each iteration simulates every motion (the convergence signal is the RMS error over all their
/// observations; the iteration diverged if any motion did), runs stages 2–4 per motion with its
/// own mesh and basis, and fits one correction to every motion's reconstruction equations
/// (centres by k-means over all their stretches). The forward fit minimises the error summed
/// over the motions. The record's counts, objectives and times are sums over the motions.
/// On return `state.best` is the learned correction (null if nothing beat the nominal model).
/// Returns false if interrupted (state is then the last checkpoint's). Throws InputError for
/// invalid inputs (with several motions the field names the motion: "motions[i].observations").
bool run_learning(std::span<const Motion> motions, const LearningOptions& options,
    LearningState& state, const LearningCallbacks& callbacks = {});

/// One motion: `scene` against `observed` (as a training set of that one motion).
bool run_learning(const sim::Scene& scene, const observe::Observation& observed,
    const LearningOptions& options, LearningState& state, const LearningCallbacks& callbacks = {});

} // namespace elastolearn::learn
