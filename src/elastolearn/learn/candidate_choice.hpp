#pragma once
/// \file Stage 4's choice among the validated candidates of the learning recipe
/// (learning_recipe.hpp, docs/learning_recipe.md): what a candidate is and what was measured of
/// it, the paired noise test against the reference (the fitted nominal), and the choice of the
/// eligible candidate with the lowest held-out error among those that beat the reference beyond
/// noise, with the larger-motion check run lazily from the best down.
#include <elastolearn/core/types.hpp>
#include <elastolearn/learn/larger_motion_check.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/material/correction.hpp>

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace elastolearn::learn {

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
  /// (check_larger_motion, reference_droop). A user's next motion is rarely the one recorded.
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
  /// The z it had to reach on the held-out data to beat the reference:
  /// significance_threshold(n) for the n corrections compared with it.
  double required_significance = 0;
  /// It beats the reference beyond noise on the held-out data: they resolve it (resolution ≥
  /// required_significance) and it gains there (significance ≥ required_significance). False
  /// for the reference itself.
  bool beats_reference = false;
  /// Eligible for the choice: its validation completed, it survives a larger motion (or was not
  /// checked for it) and it is stable where a motion of another kind may go.
  bool eligible() const { return completed && larger_motion.completed && stability.stable(); }
};

/// How many noise standard deviations a candidate must beat the fitted nominal by on the held-out
/// data to replace it when it is the only one compared (one-sided: a 2.3 % chance that noise
/// alone passes a candidate no better).
inline constexpr double kSignificance = 2;

/// The z each of `compared` corrections must reach on the held-out data to beat the reference:
/// kSignificance's one-sided chance Φ(−kSignificance) split among them (Bonferroni),
/// Φ⁻¹(1 − Φ(−kSignificance)/compared), so that noise alone passes one of them no more often
/// however many the learning proposes (2 for one, 2.43 for 3, 2.89 for 12, 3.05 for 20).
/// Without it, of a dozen independent candidates no better than the fit one passes by chance
/// a quarter of the time, and a correction chosen that way can test far worse on a larger
/// motion.
double significance_threshold(int compared);

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

/// Sets candidate i's significance, resolution, training_significance, required_significance
/// (= `threshold`) and beats_reference against the reference candidate (index `reference`), on
/// the held-out data `validation` and, if it holds predictions of both, the training data
/// `training`; σ the noise per coordinate.
void compare_with_reference(std::vector<Candidate>& candidates, size_t i, int reference,
    const ComparedData& validation, const ComparedData& training, double sigma, double threshold);

/// Stage 4's choice, `reference` the index of the fitted nominal (or −1: no reference), σ the
/// noise per coordinate. Compares every other completed candidate with the reference
/// (compare_with_reference, at significance_threshold of the number of completed corrections)
/// and returns the index of the eligible candidate with the lowest
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

} // namespace elastolearn::learn
