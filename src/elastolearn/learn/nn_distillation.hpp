#pragma once
/// \file Distillation of a learned correction (the RBF of the learning loop) into the network
/// correction of paper 000 §6.2: "We use the learned RBF parametric model and run many
/// simulations while recording principal stretches and stretch rates of elements", then train
/// the network (learn/mlp_training.hpp) on the teacher's outputs at those states. The paper's
/// 6 → 6 → 6 → 3 network becomes one 6 → 6 → 6 → 1 network g shared by the three principal
/// directions (material::NnCorrection): each state gives three training rows (x_k, N_k). Or,
/// for an RBF whose N is the gradient of an energy, an energy network ΔΨ(σ) fitted through its
/// gradient (material::NnKind::Energy). distill_rbf is the entry point from a learned RBF and its
/// training stretches.
/// Rationale and measured numbers: docs/learning.md ("Neural-network correction").
#include <elastolearn/learn/energy_mlp_training.hpp>
#include <elastolearn/learn/mlp_training.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/sim/scene.hpp>

#include <cstdint>
#include <limits>
#include <optional>
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
  /// Only element states whose principal stretches all lie in [stretch_min, stretch_max] are
  /// sampled, and jittered copies are clamped into it: the teacher's trusted stretches, beyond
  /// which teacher and network are both continued from the edge (material/trusted_stretches.hpp)
  /// and a larger motion's far states would only crowd the fit. Default: every state.
  double stretch_min = -std::numeric_limits<double>::infinity();
  double stretch_max = std::numeric_limits<double>::infinity();
  /// Throws InputError("distillation.<field>", ...) for an out-of-range field.
  void validate() const;
};

struct DistillationSampleReport {
  long states_seen = 0; ///< element states in the stretch interval over all recorded frames
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
/// A simulation whose step fails stops there, unrescued (no exact-tangent retry or substeps),
/// and contributes the frames before it (reported). Deterministic.
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
  /// Stress network (fitted to N_k per direction) or energy network (fitted to N through its
  /// gradient); see material::NnKind.
  material::NnKind kind = material::NnKind::Stress;
  /// Architecture, Adam, early stopping, seed. The defaults are the stress network's (batch norm
  /// + ELU, paper §6.2); energy_distillation_options() gives the energy network's.
  MlpTrainingOptions training;
  double validation_fraction = 0.2; ///< held-out share of the samples, in (0, 1)
  /// Energy network: the degree of the polynomial energy cᵀ m(p) fitted before the MLP: 3 (all
  /// of m), 2 (p₁, p₁², p₂: the isotropic linear stress, 2Δμ e + Δλ tr e plus a pressure) or 0
  /// (none).
  int energy_polynomial_degree = 3;
  /// Energy network: a given polynomial c instead of the least-squares fit (distill_rbf passes
  /// the teacher's tails, rbf_energy_polynomial).
  std::optional<Eigen::Matrix<double, 6, 1>> energy_polynomial;
  /// Throws InputError("distillation.<field>" or "mlp_training.<field>", ...).
  void validate() const;
};

/// The energy network's defaults: 3 → 8 → 8 → 1, squareplus (C∞, so the tangent ∇²ΔΨ is
/// continuous — ELU's f'' jumps at 0 and ReLU's vanishes — softplus-like, and algebraic, so
/// ~3× cheaper to evaluate than softplus), no batch norm (train_gradient_mlp),
/// Adam step 5·10⁻³, patience 40 (docs/learning.md, "Energy network").
NnDistillationOptions energy_distillation_options();

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

/// Train the network correction of options.kind on `samples`: distill_stress_network or
/// distill_energy_network.
NnDistillationResult distill_nn_correction(
    const StressSamples& samples, const NnDistillationOptions& options);

/// Train the stress network correction on `samples` (targets = the teacher's outputs): split the
/// states into a random validation set and a training set (the three direction rows of a state stay
/// together), turn each state into three rows (material::nn_input(σ, ḟ, k), N_teacher,k),
/// standardise inputs and the scalar output with the training rows' mean and standard deviation
/// (a constant input gets scale 1), train (train_mlp), fold batch norm, and measure the RMS errors
/// of the resulting NnCorrection in Pa per state (‖ΔN‖ over the 3 directions). Samples need not
/// be sorted. Deterministic for a given seed.
/// Throws InputError for bad options or samples (empty, mismatched, non-finite, fewer than
/// 2 samples in a split).
NnDistillationResult distill_stress_network(
    const StressSamples& samples, const NnDistillationOptions& options);

/// Train the energy network correction (material::NnKind::Energy) on `samples` (stretches and
/// targets N_teacher(σ); rates are ignored, as N does not depend on them): split the states as
/// distill_stress_network; take options.energy_polynomial as the polynomial c or fit it (terms up
/// to energy_polynomial_degree) by linear least squares to the training split's N; standardise x =
/// energy_input(σ) with the training states' mean and standard deviation and scale the residual by
/// its RMS over the RMS of the chain map D = ∂x̃/∂σ; train the MLP on the residual through its
/// gradient (train_gradient_mlp; options.training.batch_norm must be off). RMS errors as
/// distill_stress_network. Deterministic for a given seed. Throws InputError as it.
NnDistillationResult distill_energy_network(
    const StressSamples& samples, const NnDistillationOptions& options);

/// The energy polynomial c (NnKind::Energy's m(p) = (p₁, p₁², p₂, p₁³, p₁p₂, p₃)) of an RBF's
/// linear and quadratic tails: ½(a − b) p₂ + ½ b p₁² + c p₁ and α p₁³ + β p₁p₂ + γ p₃ (as
/// RbfCorrection::elastic_energy). nullopt for stress kernels or a neo-Hookean tail (not a
/// polynomial).
std::optional<Eigen::Matrix<double, 6, 1>> rbf_energy_polynomial(
    const material::RbfCorrection& rbf);

/// What distil_rbf does besides training.
struct RbfDistillationOptions {
  /// The network kind: energy for a teacher with energy kernels (its N is a gradient, and the
  /// energy network keeps that: a symmetric tangent), stress otherwise.
  std::optional<material::NnKind> kind;
  /// Jittered copies per training stretch (Gaussian, stretch_jitter), so the network also sees
  /// the neighbourhood of the observed states (Newton's trial states). ≥ 0.
  int jitter_copies = 1;
  double stretch_jitter = 0.02; ///< [-]
  /// Stress network only: rates drawn N(0, rate_sigma²) per sample [1/s]. The RBF does not depend
  /// on them, so varied rates teach the network not to either (docs/learning.md, "Samples").
  double rate_sigma = 3;
  std::uint64_t seed = 1; ///< jitter and rates
  /// Energy network: the teacher's tails as its polynomial (rbf_energy_polynomial), unless the
  /// energy options give one; false: the least-squares fit of `energy`. The fit extrapolates
  /// badly: it gives the kernels' curvature inside the data to the polynomial, which grows
  /// outside it (docs/learning.md, "Activation and batch normalisation").
  bool teacher_polynomial = true;
  NnDistillationOptions stress; ///< training of a stress network
  NnDistillationOptions energy = energy_distillation_options(); ///< of an energy network
  /// Throws InputError("distillation.<field>", ...).
  void validate() const;
};

/// The one call for distilling a learned RBF: samples at the training stretches `stretches`
/// (n × 3, any order per row; e.g. the learning loop's trajectory stretches) and their jittered
/// copies, targets N_teacher(σ), a network of options.kind (default: by the teacher's
/// energy_kernels) trained on them (distill_nn_correction; an energy network takes the teacher's
/// tails as its polynomial, rbf_energy_polynomial, so that the MLP fits the kernels alone and
/// the network extrapolates like the teacher), and the teacher's damping Δα₁ attached
/// (with_teacher_damping). The result's correction is ready to simulate with; its RMS errors
/// (relative_validation_rms()) are the distillation error against the teacher.
/// Throws InputError("distillation.<field>", ...) for bad options or stretches (fewer than 2
/// rows, not 3 columns, non-finite).
NnDistillationResult distill_rbf(const material::RbfCorrection& teacher, ConstRef<MatX> stretches,
    const RbfDistillationOptions& options = {});

} // namespace elastolearn::learn
