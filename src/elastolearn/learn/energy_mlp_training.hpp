#pragma once
/// \file Training of a scalar network by its gradient (the energy network of
/// material::NnKind::Energy): the data are stresses, not energies, so the network g: Rᵈ → R is
/// fitted through a per-sample linear map of its input gradient,
///   minimise  Σ_j ‖D_jᵀ ∇g(x_j) − t_j‖² / (m·n)   (n samples, m = rows of t)
/// with D_j = ∂x/∂σ at sample j (d × m), so that D_jᵀ ∇g = ∇_σ g(x(σ)) is the stress of the energy
/// g. The weight gradient of this loss needs the network's second derivatives: forward mode
/// carries ∂a/∂x (one tangent per input) through the layers, reverse mode runs back through both
/// the values and the tangents (double back-propagation, written out for the small MLP).
/// Adam, shuffling, step halving and early stopping as learn::train_mlp; no batch
/// normalisation (its batch statistics would couple the samples' input gradients, and the inputs
/// are standardised already). Rationale and numbers: docs/learning.md ("Energy network").
#include <elastolearn/learn/mlp_training.hpp>

#include <vector>

namespace elastolearn::learn {

/// One set of samples: inputs x (d × n, standardised), the maps D (d·m × n: column j holds D_j
/// column-major, D_j(c, i) at row c + d·i) and the targets t (m × n, standardised like the
/// network's output).
struct GradientSamples {
  MatX inputs;
  MatX maps;
  MatX targets;
};

/// D_jᵀ ∇g(x_j) for every sample (m × n), in inference mode; for checks and the loss.
MatX network_stress(const BatchNormMlp& network, const GradientSamples& samples);

/// The loss ‖D_jᵀ ∇g(x_j) − t_j‖² / (m·n) over `samples`.
double gradient_loss(const BatchNormMlp& network, const GradientSamples& samples);

/// ∂loss/∂W_k and ∂loss/∂b_k for each layer k (shapes of the layer's weight and bias).
struct MlpGradient {
  std::vector<MatX> weights;
  std::vector<VecX> biases;
};

/// The gradient of gradient_loss by double back-propagation, over kChunks fixed column ranges
/// of the samples evaluated in parallel (oneTBB) and summed in range order, so the result is the
/// same for any number of threads. Keeps its buffers between calls: one per trainer, not shared
/// between threads.
class GradientLoss {
  public:
  /// Column ranges per call: two per core of the 2-core machines the learning runs on, so a
  /// 256-sample batch is four 64-column blocks.
  static constexpr int kChunks = 4;
  GradientLoss();
  ~GradientLoss();
  GradientLoss(const GradientLoss&) = delete;
  GradientLoss& operator=(const GradientLoss&) = delete;
  /// The gradient at `network` (no batch norm) over `samples` (any number ≥ 1; ranges may be
  /// empty); valid until the next call.
  const MlpGradient& gradient(const BatchNormMlp& network, const GradientSamples& samples);

  private:
  struct Chunk;
  std::vector<Chunk> m_chunks;
};

/// Train g (hidden widths and activation from `options`, one output, no batch norm) on
/// `training`, keeping the network with the best loss on `validation` (MlpTrainingReport's losses
/// are this gradient loss). The output layer's bias does not affect the loss and stays 0.
/// Deterministic for a given seed. Throws InputError("mlp_training.<field>", ...) for bad options
/// (batch_norm must be off: "mlp_training.batch_norm"), empty or mismatched sets, or non-finite
/// data.
MlpTrainingResult train_gradient_mlp(const GradientSamples& training,
    const GradientSamples& validation, const MlpTrainingOptions& options);

} // namespace elastolearn::learn
