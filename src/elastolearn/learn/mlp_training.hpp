#pragma once
/// \file Training of the small multilayer perceptron of paper 000 §6.2 (Fig. 5): hidden layers
/// Linear → batch normalisation → activation, a linear output layer, mean-squared error, Adam on
/// shuffled mini-batches, early stopping on a held-out set, and the folding of batch
/// normalisation into the linear layers for inference (material::NnCorrection).
///
/// Hand-written on Eigen: the network has a few dozen weights, and no Debian-packaged C++
/// learning library is worth the dependency for it (they target large models, GPUs and their own
/// tensor types). Batches are Eigen matrices with one column per sample, allocated once.
/// Rationale and measured numbers: docs/learning.md ("Neural-network correction").
#include <elastolearn/core/types.hpp>
#include <elastolearn/material/nn_correction.hpp>

#include <cstdint>
#include <random>
#include <vector>

namespace elastolearn::learn {

struct MlpTrainingOptions {
  /// Hidden layer widths: the paper's 6 → 6 → 6 (→ 1 for the shared per-direction network of
  /// NnCorrection); each 1..NnCorrection::max_width, at most NnCorrection::max_hidden_layers.
  std::vector<int> hidden_widths { 6, 6 };
  bool batch_norm = true; ///< batch normalisation before each activation (paper §6.2)
  /// The hidden layers' activation: ELU (paper §6.2); Fig. 6 compares ReLU and sigmoid.
  material::Activation activation = material::Activation::Elu;
  int batch_size = 256; ///< samples per Adam step (capped at the training-set size)
  int max_epochs = 400; ///< passes over the training set
  double learning_rate = 1e-2; ///< Adam step size α (standardised units)
  double beta1 = 0.9; ///< Adam first-moment decay
  double beta2 = 0.999; ///< Adam second-moment decay
  double adam_epsilon = 1e-8;
  /// Halve the learning rate after this many epochs without a new best validation loss.
  int plateau_epochs = 8;
  /// Stop after this many epochs without a new best validation loss (early stopping).
  int patience = 25;
  /// A validation loss counts as a new best if it is below (1 − min_improvement) · best.
  double min_improvement = 1e-3;
  double batch_norm_momentum = 0.1; ///< running statistics r ← (1 − m) r + m · batch statistic
  double batch_norm_epsilon = 1e-5; ///< ε in (z − μ)/√(σ² + ε)
  std::uint64_t seed = 1; ///< weight initialisation and shuffling (same seed, same result)
  /// Throws InputError("mlp_training.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The network in training form (before folding). Layer k maps a_k to
///   z = W a_k + b;  hidden: a_{k+1} = f(γ ⊙ (z − μ) ⊘ √(v + ε) + β) with batch norm, f(z)
///   without (f = `activation`);  last layer: output z.
/// μ, v are the batch's mean and (biased) variance in training mode and the running statistics
/// in inference mode. Hidden layers with batch norm keep b = 0 (β replaces it).
struct BatchNormMlp {
  struct Layer {
    MatX weight; ///< out × in
    VecX bias; ///< out
    VecX gamma, beta; ///< batch-norm scale and shift (out), empty without batch norm
    VecX running_mean, running_var; ///< batch-norm inference statistics (out), idem
    bool has_batch_norm() const { return gamma.size() > 0; }
  };
  std::vector<Layer> layers;
  double batch_norm_epsilon = 1e-5;
  material::Activation activation = material::Activation::Elu; ///< f of the hidden layers

  int inputs() const { return static_cast<int>(layers.front().weight.cols()); }
  int outputs() const { return static_cast<int>(layers.back().weight.rows()); }
};

enum class BatchNormMode {
  Training, ///< normalise with the batch's own statistics (running statistics untouched)
  Inference, ///< normalise with the running statistics
};

/// A freshly initialised network: Glorot-uniform weights from `seed`, zero biases, γ = 1, β = 0,
/// running mean 0 and variance 1. Throws InputError("mlp_training.hidden_widths", ...) for a
/// width outside 1..NnCorrection::max_width, or if inputs/outputs < 1.
BatchNormMlp make_batch_norm_mlp(int inputs, const std::vector<int>& hidden_widths, int outputs,
    bool batch_norm, std::uint64_t seed);

/// Network outputs (outputs × B) for inputs `x` (inputs × B, one column per sample).
MatX evaluate(const BatchNormMlp& network, ConstRef<MatX> x, BatchNormMode mode);

/// The inference-mode network with each batch norm folded into its linear layer:
///   W' = diag(s) W,  b' = s ⊙ (b − μ) + β,  s = γ ⊘ √(v + ε)   (running μ, v),
/// so that the returned layers (the activation after all but the last) give
/// evaluate(…, Inference).
std::vector<material::NnCorrection::Layer> fold_batch_norm(const BatchNormMlp& network);

struct MlpTrainingReport {
  int epochs = 0; ///< epochs run
  int best_epoch = 0; ///< epoch (1-based) of the returned network
  bool stopped_early = false; ///< patience ran out before max_epochs
  double training_loss = 0; ///< mean squared error per output, inference mode, best network
  double validation_loss = 0; ///< idem on the validation set
  std::vector<double> validation_history; ///< validation loss after each epoch
  double seconds = 0; ///< wall time
};

struct MlpTrainingResult {
  BatchNormMlp network; ///< the network with the lowest validation loss
  MlpTrainingReport report;
};

/// Minimise the mean squared error ‖f(x) − y‖²/(outputs·B) over shuffled mini-batches with Adam
/// (bias-corrected moments), in training mode; after each epoch evaluate the validation loss in
/// inference mode, keep the best network, halve the step after `plateau_epochs` and stop after
/// `patience` epochs without improvement. Inputs and targets should be standardised (zero mean,
/// unit variance per row). Columns are samples. Deterministic for a given seed.
/// Throws InputError("mlp_training.<field>", ...) for bad options, empty or mismatched sets, or
/// non-finite data.
MlpTrainingResult train_mlp(ConstRef<MatX> training_inputs, ConstRef<MatX> training_targets,
    ConstRef<MatX> validation_inputs, ConstRef<MatX> validation_targets,
    const MlpTrainingOptions& options);

/// Adam moments of one parameter array (learn/energy_mlp_training.hpp trains with them too).
struct AdamMoments {
  MatX m, v;
  explicit AdamMoments(const MatX& like)
      : m(MatX::Zero(like.rows(), like.cols()))
      , v(MatX::Zero(like.rows(), like.cols())) { }
};

/// One Adam update of `param` with gradient `grad` (step size already bias-corrected).
template <typename P, typename G>
void adam_update(
    P& param, const G& grad, AdamMoments& s, const MlpTrainingOptions& o, double step) {
  s.m = o.beta1 * s.m + (1 - o.beta1) * grad;
  s.v = o.beta2 * s.v + (1 - o.beta2) * grad.cwiseAbs2();
  param.array() -= step * s.m.array() / (s.v.array().sqrt() + o.adam_epsilon);
}

/// Adam's bias-corrected step size after `steps` updates.
double adam_step(const MlpTrainingOptions& o, double learning_rate, long steps);

/// Early stopping and step halving on the validation loss (MlpTrainingOptions::plateau_epochs,
/// patience, min_improvement), shared by the trainers.
struct EarlyStopping {
  double best;
  int since_best = 0, since_decay = 0;
  /// Record an epoch's loss: true if it is a new best; halves `learning_rate` on a plateau and
  /// sets `stop` when patience runs out.
  bool update(double loss, const MlpTrainingOptions& o, double& learning_rate, bool& stop);
};

/// Portable random draws for the training code (the std distributions differ between standard
/// libraries; these give the same numbers everywhere for a seed).
/// Uniform in [0, 1) from the top 53 bits of one draw.
double uniform01(std::mt19937_64& rng);
/// Standard normal (Box–Muller, two uniform draws per call).
double standard_normal(std::mt19937_64& rng);
/// Fisher–Yates shuffle of `values` in place.
void shuffle_in_place(std::vector<int>& values, std::mt19937_64& rng);

} // namespace elastolearn::learn
