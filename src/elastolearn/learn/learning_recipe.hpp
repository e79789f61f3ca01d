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
///      (z ≥ significance_threshold of the number compared), the one with the smallest RMS error
///      there whose material survives a larger motion and a droop (kLargerMotion; checked in that
///      order, the best first, until one passes) is the result; the fitted nominal if none, also
///      where the held-out data cannot resolve a candidate from it (a motion that has died out
///      under noise: the training data, which cannot see how a candidate forecasts, are compared
///      and reported, not used; candidate_choice.hpp);
///   5. network: a chosen correction is distilled into the network correction
///      (network_distillation.hpp), validated the same way, and replaces its teacher when it is
///      eligible, beats the fitted nominal by its teacher's threshold, and is as good as its
///      teacher (network_replaces_teacher); it is several times cheaper to evaluate.
/// The validation choice is what makes the result never worse than fitting parameters on data
/// nobody tuned the recipe for: the fitted nominal is always a candidate.
#include <elastolearn/learn/candidate_choice.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/learn/network_distillation.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
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

/// Everything the recipe decided and measured.
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

/// Run all stages (from `resume` on, if given: stage 2 is then not repeated). Returns with
/// `interrupted` set if callbacks.loop.interrupted asked to stop (the last checkpoint holds the
/// state). Throws InputError for invalid inputs (no motion, an observation that does not fit its
/// scene, a nominal material with a correction or without parameters to fit).
RecipeResult learn_material(std::span<const Motion> motions, const RecipeOptions& options = {},
    const RecipeCallbacks& callbacks = {}, const RecipeResume* resume = nullptr);

} // namespace elastolearn::learn
