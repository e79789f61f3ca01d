#pragma once
/// \file The one way to learn (docs/learning_recipe.md): from one or more recorded motions of an
/// object, each a scene with the nominal material and its observations, produce the material that
/// predicts held-out data best. The stages, each a function below:
///   0. noise: σ of the observations, given or estimated (observe/observation_noise.hpp);
///   1. split: every motion's last `validation_fraction` of the frames are held out for
///      validation, the rest is the training data. The training positions the loop's space-time
///      stages follow are smoothed in time to σ (from the training frames alone), never
///      differentiated raw, while every comparison of a simulation with the data uses the
///      recorded positions (Motion::smoothed);
///   2. parameter fit: E, ν, α₀, α₁ of the nominal model fitted to the training data;
///   3. learning loop (learning_loop.hpp) on the fitted nominal, then the forward fit, whose
///      steps must be stable where stage 4 will check its last one (the reachable stretches of
///      the fitted nominal's runs of the whole motions);
///   4. validation: every candidate (the given nominal, reported but not chosen beside a
///      fitted one; the fitted nominal; the loop's corrections with the lowest training errors
///      and the forward fit's last accepted step with the earlier ones on its plateau, within 1 %
///      of its training error) simulates the held-out data; among those that are stable where
///      another motion may go and beat the fitted nominal by more than noise could
///      (z ≥ kSignificance), the one with the smallest RMS error there whose material survives a
///      larger motion and a droop (kLargerMotion; checked in that order, the best first, until
///      one passes) is the result; the fitted nominal if none, also where the
///      held-out data cannot resolve a candidate from it (a motion that has died out under
///      noise: the training data, which cannot see how a candidate forecasts, are compared and
///      reported, not used; choose_candidate);
///   5. network: a chosen correction is distilled into the network correction
///      (network_distillation.hpp), validated the same way, and replaces its teacher when it is
///      eligible, beats the fitted nominal by kSignificance, and is as good as its teacher
///      (network_replaces_teacher); it is several times cheaper to evaluate.
/// The validation choice is what makes the result never worse than fitting parameters on data
/// nobody tuned the recipe for: the fitted nominal is always a candidate.
#include <elastolearn/learn/larger_motion_check.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/learn/network_distillation.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace elastolearn::learn {

struct RecipeOptions {
  /// Observation noise σ [m] (standard deviation per coordinate); < 0: estimated from the data.
  double noise = -1;
  /// The fraction of every motion's frames, at its end, held out for validation.
  double validation_fraction = 0.2;
  /// Stage 2; its `parameters` say which of E, ν, α₀, α₁ move.
  bool fit_parameters = true;
  ParameterFitOptions parameter_fit;
  /// Stage 3 (the loop's forward_fit.max_iterations steps follow it).
  LearningOptions loop;
  /// Stage 5.
  NetworkOptions network;
  /// The recipe's defaults: a parameter fit of ≤ 20 Levenberg–Marquardt iterations; the loop
  /// backtracking, with energy kernels, the smoothness penalty and stability cuts; up to 8
  /// forward-fit steps after it, stopped at a gain below 1 %.
  RecipeOptions();
  /// Throws InputError("learn.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// How σ was obtained.
struct NoiseLevel {
  double sigma = 0; ///< [m]
  bool estimated = true; ///< false: given by the user
  double smoothing_residual = 0; ///< RMS change of the positions by the temporal smoothing [m]
};

/// What the validation compares.
enum class CandidateKind { Nominal, FittedNominal, Loop, ForwardFit, Network };
std::string to_string(CandidateKind kind);

struct Candidate {
  CandidateKind kind = CandidateKind::Nominal;
  /// The loop's (or forward fit's) iteration, a network's teacher's; −1 for the nominals.
  int iteration = -1;
  /// The material's correction (null for the nominals; an RBF, or for CandidateKind::Network the
  /// network correction); its elastic model is the fitted nominal's except for
  /// CandidateKind::Nominal.
  std::shared_ptr<const material::Correction> correction;
  /// CandidateKind::Network: the index of the candidate it was distilled from, and its gain over
  /// it in noise standard deviations (paired_significance; negative: worse than its teacher).
  int teacher = -1;
  double gain_over_teacher = 0;
  bool completed = false; ///< the validation simulation completed
  std::string failure; ///< why it did not (names the motion and the frame); empty if it did
  ErrorSummary validation; ///< at the held-out observations [m]
  /// Whether its material survives a larger motion: every held-out motion's scene driven
  /// kLargerMotion times as hard (sim::amplified_scene) must simulate to its end (substeps
  /// allowed), and the object must hold its droop under a body load as large
  /// (check_larger_motion, droop_acceleration). A user's next motion is rarely the one recorded.
  /// Not checked (passed) for the nominals, nor for a correction the choice did not reach: the
  /// check costs a harder run of every motion and a static solve, so it runs on the best
  /// candidate first and stops at the first that passes (learn_material).
  LargerMotionCheck larger_motion;
  /// Its material at the stretches a motion of another kind may reach (reachable_stretches of
  /// the fitted nominal's runs of the held-out motions): a correction must be stable there. Not
  /// checked (stable) for the nominals.
  StabilityReport stability;
  /// At the training observations as recorded [m], from the run of its validation (each motion
  /// is simulated whole).
  ErrorSummary training;
  /// Its improvement on the reference (the fitted nominal, or the given one without a fit) in
  /// standard deviations of what noise alone would give: z = (‖r − o‖² − ‖c − o‖²) / (2σ‖c − r‖)
  /// over the held-out observations o, with r, c the reference's and this candidate's predictions
  /// (the noise term of the difference, −2 nᵀ(c − r), has standard deviation 2σ‖c − r‖). 0 for
  /// the reference itself.
  double significance = 0;
  /// How far the held-out data can tell it from the reference: the z it would reach there if it
  /// were exactly right, ‖c − r‖ / (2σ) (+∞ without noise, 0 for the reference). Below
  /// kSignificance no candidate, however good, could pass the held-out test: the held-out frames
  /// barely move (a damped motion's tail) or the candidate barely differs there.
  double resolution = 0;
  /// The unknowns fitted to the training data (a correction's weights and tails; a network's
  /// teacher's): the degrees of freedom training_significance charges. 0 for the nominals.
  int unknowns = 0;
  /// Its improvement on the reference over the training observations, charged for what fitting
  /// its unknowns to their noise gains by itself (k σ² in expectation, k = unknowns):
  /// z = (‖r − o‖² − ‖c − o‖² − k σ²) / (2σ‖c − r‖). NaN where not measured. Reported (what the
  /// training data say where the held-out data cannot resolve a candidate), not used by the
  /// choice: fitting the training frames better says nothing of how a candidate forecasts.
  double training_significance = std::numeric_limits<double>::quiet_NaN();
  /// It beats the reference beyond noise on the held-out data: they resolve it (resolution ≥
  /// kSignificance) and it gains there (significance ≥ kSignificance). False for the reference
  /// itself.
  bool beats_reference = false;
  /// Eligible for the choice: its validation completed, it survives a larger motion (or was not
  /// checked for it) and it is stable where a motion of another kind may go.
  bool eligible() const { return completed && larger_motion.completed && stability.stable(); }
};

/// Everything the recipe decided and measured.
/// How many noise standard deviations a candidate must beat the fitted nominal by on the held-out
/// data to replace it (one-sided: a 2.3 % chance that noise alone passes a candidate no better).
inline constexpr double kSignificance = 2;

struct RecipeResult {
  /// Per motion, the observations learned from: for a point-cloud capture those derived from its
  /// clouds (cloud_motion.hpp), else the motion's own.
  std::vector<observe::Observation> observed;
  NoiseLevel noise;
  int training_frames = 0; ///< frames of the first motion trained on (the split)
  int validation_frames = 0; ///< frames compared in validation (summed over the motions)
  std::string
      validation_data; ///< what was held out: "the last 20 %: 20 of 100 frames of <name>, …"
  ParameterFitReport parameter_fit; ///< stage 2 (its `fitted` = the given nominal if skipped)
  material::ElasticModelType nominal_type {};
  fem::MaterialModel fitted_nominal; ///< the nominal material with the fitted parameters
  LearningState loop; ///< stage 3's final state (history, best)
  /// Stage 5's distillation, if it ran (its candidate is the last one).
  std::optional<NetworkDistillation> network;
  std::vector<Candidate> candidates;
  int chosen = -1; ///< index into candidates
  double seconds = 0;
  bool interrupted = false; ///< stopped at a checkpoint; nothing was chosen
  const Candidate& choice() const { return candidates.at(static_cast<size_t>(chosen)); }
  /// Candidate `candidate`'s material (−1: the chosen one): the fitted nominal (or, for
  /// CandidateKind::Nominal, the given one) with its correction.
  fem::MaterialModel material(const fem::MaterialModel& given_nominal, int candidate = -1) const;
};

struct RecipeCallbacks {
  std::function<void(const std::string&)> message; ///< one line per stage event
  /// After stage 2 (a checkpoint stores it with the loop's state: RecipeResume).
  std::function<void(const ParameterFitReport&)> parameters_fitted;
  LearningCallbacks loop; ///< the loop's (its checkpoint is the caller's business)
};

/// Where a resumed run continues: the stage-2 result and the loop's state, both from a checkpoint.
struct RecipeResume {
  ParameterFitReport parameter_fit;
  LearningState loop;
};

/// The nominal parameters (E, ν, α₀, α₁) and model type of a scene's material; throws
/// InputError("material", ...) if the elastic model has no single (E, ν) or the damping is not
/// constant Rayleigh damping (fit-parameters needs both).
NominalParameters nominal_parameters_of(
    const fem::MaterialModel& material, material::ElasticModelType& type);

/// A paired test of candidate predictions `c` against reference predictions `r` of the
/// observations `o` with noise σ per coordinate: z = (‖r − o‖² − ‖c − o‖²) / (2σ‖c − r‖), the
/// gain in standard deviations of what noise alone would give (the noise term of the difference,
/// −2 nᵀ(c − r), has standard deviation 2σ‖c − r‖). ±∞ (0 if c = r) when σ‖c − r‖ = 0.
double paired_significance(const VecX& r, const VecX& c, const VecX& o, double sigma);

/// How much larger than its teacher's a network's validation RMS may be and still count as
/// "as good", whatever the noise: with exact data (σ → 0) the paired test calls any difference
/// significant, and a network that reproduces its teacher to a fraction of a per cent (its
/// distillation error) predicts the held-out data within rounding of the teacher's prediction.
inline constexpr double kNetworkTolerance = 0.01;

/// Stage 5's decision: a network candidate replaces its teacher when it is eligible, beats the
/// reference (beats_reference, unless `has_reference` is false) and is as good as its teacher:
/// not worse by kSignificance noise deviations, or its validation RMS within
/// (1 + kNetworkTolerance) of the teacher's.
bool network_replaces_teacher(
    const Candidate& network, const Candidate& teacher, bool has_reference);

/// Observations and every candidate's prediction of them, flat (frame, observed vertex, xyz; 0
/// at lost entries; a prediction is empty where the candidate's simulation did not complete).
struct ComparedData {
  std::vector<VecX> predictions;
  VecX observed;
};

/// Sets candidate i's significance, resolution, training_significance and beats_reference
/// against the reference candidate (index `reference`), on the held-out data `validation` and,
/// if it holds predictions of both, the training data `training`; σ the noise per coordinate.
void compare_with_reference(std::vector<Candidate>& candidates, size_t i, int reference,
    const ComparedData& validation, const ComparedData& training, double sigma);

/// Stage 4's choice, `reference` the index of the fitted nominal (or −1: no reference), σ the
/// noise per coordinate. Compares every other completed candidate with the reference
/// (compare_with_reference) and returns the index of the eligible candidate with the lowest
/// validation RMS among the reference and the candidates that beat it on the held-out data
/// (`training`, if it holds predictions, only sets their training_significance). With a
/// reference, the given nominal (CandidateKind::Nominal) is compared but never chosen. −1 if no
/// candidate is eligible.
int choose_candidate(std::vector<Candidate>& candidates, const ComparedData& validation,
    const ComparedData& training, int reference, double sigma);

/// Stage 4's choice with the larger-motion check run lazily: choose_candidate, and while the
/// choice is a correction not yet checked, `check_larger_motion` sets its
/// Candidate::larger_motion and the choice is made again (the candidate is then checked, and
/// ineligible if it failed). Only the chosen correction and those the choice would have
/// preferred are checked, each once. −1 if no candidate is eligible.
int choose_checked_candidate(std::vector<Candidate>& candidates, const ComparedData& validation,
    const ComparedData& training, int reference, double sigma,
    const std::function<void(Candidate&)>& check_larger_motion);

/// Run all stages (from `resume` on, if given: stage 2 is then not repeated). Returns with
/// `interrupted` set if callbacks.loop.interrupted asked to stop (the last checkpoint holds the
/// state). Throws InputError for invalid inputs (no motion, an observation that does not fit its
/// scene, a nominal material with a correction or without parameters to fit).
RecipeResult learn_material(std::span<const Motion> motions, const RecipeOptions& options = {},
    const RecipeCallbacks& callbacks = {}, const RecipeResume* resume = nullptr);

} // namespace elastolearn::learn
