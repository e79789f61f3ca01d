#pragma once
/// \file The neural-network material correction of paper 000 §6.2 (Eq. 1, Fig. 5): a small
/// multilayer perceptron N(F̂, Ḟ̂) distilled from the learned RBF correction
/// (learn/nn_distillation.hpp). Rationale and measured numbers: docs/learning.md.
#include <elastolearn/material/correction.hpp>

#include <vector>

namespace elastolearn::material {

/// N(σ, ḟ) = μ_y + s_y ⊙ MLP((x − μ_x) ⊘ s_x), x = (σ, ḟ) ∈ R⁶, with
///   MLP = L_K ∘ ELU ∘ L_{K−1} ∘ … ∘ ELU ∘ L_1,   L_k(a) = W_k a + b_k,
///   ELU(z) = z for z > 0, eᶻ − 1 otherwise (α = 1, so ELU is C¹).
/// The batch-normalisation layers of training (paper §6.2: "ELU activation functions after a
/// batch normalization layer") are folded into W_k, b_k at inference, so they do not appear here.
///
/// Permutation symmetry: as RbfCorrection, the stretches are sorted descending (stable, rates
/// permuted alike) before evaluation and the outputs permuted back, so N(Pσ, Pḟ) = P N(σ, ḟ)
/// exactly; the network itself only ever sees sorted stretches.
/// `correction` and `correction_gradient` are exact (forward-mode differentiation through ELU),
/// allocation-free (stack buffers; hidden widths ≤ max_width) and thread-safe.
class NnCorrection final : public Correction {
  public:
  /// Largest hidden-layer width evaluation supports without allocating.
  static constexpr int max_width = 32;

  struct Layer {
    MatX weight; ///< out × in
    VecX bias; ///< out
  };
  struct Parameters {
    /// x̃ = (x − input_mean) ⊘ input_scale, x = (σ [-], ḟ [1/s]); scales > 0.
    Eigen::Matrix<double, 6, 1> input_mean = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 1> input_scale = Eigen::Matrix<double, 6, 1>::Ones();
    /// N = output_mean + output_scale ⊙ y [Pa]; scales > 0.
    Vec3 output_mean = Vec3::Zero();
    Vec3 output_scale = Vec3::Ones();
    /// Hidden layers (followed by ELU) then the linear output layer: the first takes 6
    /// inputs, each takes the previous layer's outputs, the last has 3 outputs; hidden widths
    /// 1 … max_width. At least one layer.
    std::vector<Layer> layers;
  };

  /// Throws InputError("nn_correction.<field>", ...) — e.g. "nn_correction.layers[1].weight" —
  /// if the layers are missing or their sizes do not chain 6 → … → 3, a hidden width exceeds
  /// max_width, a value is not finite, or a scale is not positive.
  explicit NnCorrection(Parameters parameters);

  std::string name() const override { return "nn"; }
  Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const override;
  void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  std::unique_ptr<Correction> clone() const override;

  const Parameters& parameters() const { return m_p; }

  private:
  /// Evaluate at sorted stretches s and rates f; ∂N/∂(s, f) (3×6) if `jacobian` is non-null.
  Vec3 evaluate_sorted(const Vec3& s, const Vec3& f, Eigen::Matrix<double, 3, 6>* jacobian) const;
  Parameters m_p;
};

} // namespace elastolearn::material
