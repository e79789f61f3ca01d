#pragma once
/// \file Distillation of a learned correction (the RBF of the learning loop) into the network
/// correction of paper 000 §6.2: "We use the learned RBF parametric model and run many
/// simulations while recording principal stretches and stretch rates of elements", then train
/// the network (learn/mlp_training.hpp) on the teacher's outputs at those states. The paper's
/// 6 → 6 → 6 → 3 network becomes one 6 → 6 → 6 → 1 network g shared by the three principal
/// directions (material::NnCorrection): each state gives three training rows (x_k, N_k).
/// Rationale and measured numbers: docs/learning.md ("Neural-network correction").
#include <elastolearn/learn/mlp_training.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/sim/scene.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace elastolearn::learn {

struct DistillationSampleOptions {
  /// Element states (one element at one frame) kept over all scenes: a uniform random subsample
  /// (reservoir sampling, so memory stays O(recorded_samples)). ≥ 1.
  int recorded_samples = 25000;
  int frame_stride = 1; ///< record every frame_stride-th frame (frame 0 = initial state); ≥ 1
  /// Jittered copies per recorded state, to cover its neighbourhood (total samples
  /// = recorded · (1 + jitter_copies)). ≥ 0.
  int jitter_copies = 1;
  double stretch_jitter = 0.02; ///< standard deviation of the Gaussian stretch jitter [-]
  /// Standard deviation of the rate jitter, relative to the RMS recorded stretch rate [-]. Large on
  /// purpose: other motions (and Newton trials) reach rates far above the recorded ones, and a
  /// network only learns the teacher's rate response where the samples vary the rates
  /// (docs/learning.md: 0.25 made Newton fail at the first step, 10 at a faster test motion).
  double rate_jitter = 50;
  std::uint64_t seed = 1; ///< subsampling and jitter (same seed, same samples)
  /// Throws InputError("distillation.<field>", ...) for an out-of-range field.
  void validate() const;
};

struct DistillationSampleReport {
  long states_seen = 0; ///< element states over all recorded frames of all scenes
  int recorded = 0; ///< kept after subsampling
  int jittered = 0; ///< jittered samples added
  int scenes_completed = 0; ///< simulations that ran all their frames
  std::vector<std::string> messages; ///< why a simulation stopped early (its frames are kept)
};

/// Simulate every scene with `teacher` as its correction (replacing any correction the scene
/// has), record each element's principal stretches and stretch rates (sorted descending, rates
/// permuted alike) at every frame_stride-th frame, keep a uniform random subsample of
/// `recorded_samples` states over all scenes, add `jitter_copies` Gaussian-jittered copies of each,
/// and evaluate the teacher on all of them: targets = N_teacher(σ, ḟ) [Pa], the elastic
/// correction only. The teacher's damping correction Δα₁ is not distilled (paper §6.2 lets the
/// network carry it through ḟ): as a function of (σ, ḟ) it misses the shear modes that
/// −Δα₁ K_e v_e damps, and its large rate-driven targets cost the elastic part enough accuracy
/// that the network's simulations diverged (docs/learning.md). with_teacher_damping carries it
/// over exactly instead.
/// A simulation that diverges contributes the frames before it (reported). Deterministic.
/// Throws InputError for bad options, no scenes, or no recorded state at all.
StressSamples distillation_samples(std::span<const sim::Scene> scenes,
    const material::Correction& teacher, const DistillationSampleOptions& options,
    DistillationSampleReport* report = nullptr);

/// `network` with the teacher's damping correction Δα₁ attached unchanged (an RBF teacher's
/// damping_part, a network teacher's damping; none if the teacher has none), replacing any it had.
/// Throws InputError("distillation.teacher", ...) for another kind of teacher with damping.
material::NnCorrection with_teacher_damping(
    const material::NnCorrection& network, const material::Correction& teacher);

/// Convenience: distillation_samples over scaled_motions(scene, motion_scales), i.e. the scene's
/// motion at several amplitudes (e.g. {0.5, 1, 1.5}); an empty list means {1}.
StressSamples distillation_samples(const sim::Scene& scene, std::span<const double> motion_scales,
    const material::Correction& teacher, const DistillationSampleOptions& options,
    DistillationSampleReport* report = nullptr);

/// Copies of `scene` whose motion is scaled by each factor: gravity, initial velocity and angular
/// velocity, static (initial) loads, point loads, keyframe amplitudes/offsets and a recorded
/// initial state's displacement and velocities are multiplied by the factor (the mesh and
/// material are kept), and the copy's name gets a "_x<factor>"
/// suffix. Every driver is scaled alike, so in the linear regime the displacements scale by the
/// factor (a scene driven by gravity alone, e.g. a droop, would otherwise not change at all).
/// Training on several amplitudes covers more of the stretch space than the one observed motion.
/// Throws InputError("distillation.motion_scales", ...) for a non-finite factor.
std::vector<sim::Scene> scaled_motions(const sim::Scene& scene, std::span<const double> scales);

struct NnDistillationOptions {
  MlpTrainingOptions training; ///< architecture, Adam, early stopping, seed
  double validation_fraction = 0.2; ///< held-out share of the samples, in (0, 1)
  /// Throws InputError("distillation.<field>" or "mlp_training.<field>", ...).
  void validate() const;
};

struct NnDistillationResult {
  material::NnCorrection correction; ///< the folded network with its standardisation
  MlpTrainingReport training; ///< losses in standardised units, history, epochs, time
  int training_samples = 0; ///< states in the training split (3 rows each)
  int validation_samples = 0; ///< states in the validation split (3 rows each)
  double training_rms = 0; ///< √(mean ‖N_nn − N_teacher‖²) over the training split [Pa]
  double validation_rms = 0; ///< idem over the validation split [Pa]
  double target_rms = 0; ///< √(mean ‖N_teacher‖²) over all samples [Pa]
  double relative_training_rms() const { return training_rms / target_rms; }
  double relative_validation_rms() const { return validation_rms / target_rms; }
};

/// Train the network correction on `samples` (targets = the teacher's outputs): split the states
/// into a random validation set and a training set (the three direction rows of a state stay
/// together), turn each state into three rows (material::nn_input(σ, ḟ, k), N_teacher,k),
/// standardise inputs and the scalar output with the training rows' mean and standard deviation
/// (a constant input gets scale 1), train (train_mlp), fold batch norm, and measure the RMS errors
/// of the resulting NnCorrection in Pa per state (‖ΔN‖ over the 3 directions). Samples need not
/// be sorted. Deterministic for a given seed.
/// Throws InputError for bad options or samples (empty, mismatched, non-finite, fewer than
/// 2 samples in a split).
NnDistillationResult distill_nn_correction(
    const StressSamples& samples, const NnDistillationOptions& options);

} // namespace elastolearn::learn
