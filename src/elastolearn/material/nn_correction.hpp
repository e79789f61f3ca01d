#pragma once
/// \file The neural-network material correction of paper 000 §6.2 (Eq. 1, Fig. 5): a small
/// multilayer perceptron distilled from the learned RBF correction (learn/nn_distillation.hpp),
/// isotropic by construction like the RBF (one scalar network per principal direction's view).
/// Rationale and measured numbers: docs/learning.md ("Neural-network correction").
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <memory>
#include <vector>

namespace elastolearn::material {

/// The 6 network inputs seen by principal direction k ∈ {0, 1, 2}, with a, b the other two:
///   x_k = (σ_k, σ_a + σ_b, ½(σ_a − σ_b)²,                  the smooth invariants of the view
///          ḟ_k, ḟ_a + ḟ_b, (σ_a − σ_b)(ḟ_a − ḟ_b))         and their time derivatives.
/// The stretch part carries the same information as RbfCorrection's stretch view (σ_k,
/// max(σ_a, σ_b), min(σ_a, σ_b)) but is C∞: max/min have a kink at σ_a = σ_b, where a fitted
/// network's ∂/∂max and ∂/∂min differ by the fitting error — at rest, where every element
/// starts, that kink made Newton stall (docs/learning.md). The rate part is the time derivative
/// of the stretch part: it is unchanged by swapping a and b, so continuous where σ_a and σ_b cross
/// (rates ordered like the stretches would jump there), C∞ in the rates (unlike |ḟ_a − ḟ_b|,
/// kinked at equal rates, e.g. at rest), and it keeps the sign of the correlation "the larger of
/// σ_a, σ_b is also the faster". Units: [-], [-], [-], [1/s], [1/s], [1/s].
/// Symmetric in the exact floating-point sense: swapping a and b gives the same bits.
using NnInput = Eigen::Matrix<double, 6, 1>;
NnInput nn_input(const Vec3& stretches, const Vec3& stretch_rates, int k);

/// N_k(σ, ḟ) = g(x_k), k = 1, 2, 3, with x_k = nn_input(σ, ḟ, k) and one scalar network
///   g(x)  = μ_y + s_y · MLP((x − μ_x) ⊘ s_x)                                       [Pa]
///   MLP   = L_K ∘ ELU ∘ L_{K−1} ∘ … ∘ ELU ∘ L_1,   L_k(a) = W_k a + b_k,  L_K: R^w → R,
///   ELU(z) = z for z > 0, eᶻ − 1 otherwise (α = 1, so ELU is C¹).
/// The batch-normalisation layers of training (paper §6.2: "ELU activation functions after a
/// batch normalization layer") are folded into W_k, b_k at inference, so they do not appear here.
///
/// Isotropic by construction (as RbfCorrection's h(y_k)): N(Pσ, Pḟ) = P N(σ, ḟ) exactly for every
/// permutation P, and N_i = N_j exactly whenever σ_i = σ_j and ḟ_i = ḟ_j — in particular at zero
/// rate (the elastic part), so P = U diag(P̂ + N) Vᵀ does not depend on the arbitrary U, V at
/// repeated stretches. The paper's 6 → 6 → 6 → 3 map of sorted stretches becomes a 6 → 6 → 6 → 1
/// map shared by the three directions.
/// N is C¹ in (σ, ḟ) (ELU is C¹, the inputs C∞). `correction` and `correction_gradient` are
/// exact (reverse-mode differentiation through ELU), allocation-free (stack buffers; hidden widths
/// ≤ max_width, ≤ max_hidden_layers hidden layers) and thread-safe.
class NnCorrection final : public Correction {
  public:
  /// Largest hidden-layer width evaluation supports without allocating.
  static constexpr int max_width = 32;
  /// Most hidden layers evaluation supports without allocating.
  static constexpr int max_hidden_layers = 8;

  struct Layer {
    MatX weight; ///< out × in
    VecX bias; ///< out
  };
  struct Parameters {
    /// x̃ = (x − input_mean) ⊘ input_scale for x = nn_input(σ, ḟ, k); scales > 0.
    NnInput input_mean = NnInput::Zero();
    NnInput input_scale = NnInput::Ones();
    /// g = output_mean + output_scale · y [Pa], the same for all three directions; scale > 0.
    double output_mean = 0;
    double output_scale = 1;
    /// Hidden layers (followed by ELU) then the linear output layer: the first takes 6 inputs,
    /// each takes the previous layer's outputs, the last has 1 output; hidden widths
    /// 1 … max_width, at most max_hidden_layers hidden layers. At least one layer.
    std::vector<Layer> layers;
    /// The stiffness-damping correction Δα₁(σ) of paper Eq. 13, kept as the teacher's damping
    /// RBF (material::damping_part) instead of being distilled: a function of (σ, ḟ) cannot
    /// carry −Δα₁ K_e v_e's shear modes, and a network fitted to both parts at once missed the
    /// elastic part enough that its simulations diverged (docs/learning.md). Null = no damping
    /// correction. Its elastic part must be zero.
    std::shared_ptr<const RbfCorrection> damping;
  };

  /// Throws InputError("nn_correction.<field>", ...) — e.g. "nn_correction.layers[1].weight" —
  /// if the layers are missing, too many, or their sizes do not chain 6 → … → 1, a hidden width
  /// exceeds max_width, a value is not finite, a scale is not positive, or `damping` has an
  /// elastic part.
  explicit NnCorrection(Parameters parameters);

  std::string name() const override { return "nn"; }
  Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const override;
  void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  std::unique_ptr<Correction> clone() const override;
  /// Δα₁(σ) of `damping` (0 without one).
  double stiffness_damping(const Vec3& stretches) const override {
    return m_p.damping ? m_p.damping->stiffness_damping(stretches) : 0;
  }

  /// g(x) [Pa] at one network input x (e.g. nn_input(σ, ḟ, k)) and, if `d_input` is non-null,
  /// ∂g/∂x.
  double evaluate(const NnInput& x, NnInput* d_input = nullptr) const;

  const Parameters& parameters() const { return m_p; }

  private:
  Parameters m_p;
};

} // namespace elastolearn::material
