#pragma once
/// \file The neural-network material correction of paper 000 §6.2 (Eq. 1, Fig. 5): a small
/// multilayer perceptron distilled from the learned RBF correction (learn/nn_distillation.hpp),
/// isotropic by construction like the RBF, in one of two forms: a stress network (one scalar
/// network per principal direction's view) or an energy network (one scalar ΔΨ(σ) whose gradient
/// is N). Rationale and measured numbers: docs/learning.md ("Neural-network correction").
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/nn_activation.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <array>
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

/// The power sums of e = σ − 1: p = (Σ e_k, Σ e_k², Σ e_k³) [-]. They generate every symmetric
/// polynomial of the stretches (Newton's identities), so a smooth function of p is a smooth
/// isotropic energy, the same for every ordering of σ.
Vec3 power_sums(const Vec3& stretches);

/// ε of energy_input [-]: the strain below which its second and third inputs are quadratic and
/// cubic in e (as p₂, p₃), above which they grow linearly.
constexpr double energy_input_epsilon = 0.05;

/// The 3 inputs of the energy network, smooth functions of p = power_sums(σ) that all grow
/// linearly with the strain:
///   x = (p₁, q, p₃/q²),   q = √(p₂ + ε²),  ε = energy_input_epsilon                 [-]
/// p₂ and p₃ themselves grow like ‖e‖² and ‖e‖³, so at twice the training's strain they lie
/// 4× and 8× as far out as p₁, and a network of them extrapolated far worse (docs/learning.md,
/// "Energy network"). `d_p`, if not null, receives ∂x/∂p (rows = x).
Vec3 energy_input(const Vec3& stretches, Mat3* d_p = nullptr);

/// What the network represents.
enum class NnKind {
  /// N_k(σ, ḟ) = g(x_k), k = 1, 2, 3, with x_k = nn_input(σ, ḟ, k) and one scalar network
  ///   g(x)  = μ_y + s_y · MLP((x − μ_x) ⊘ s_x)                                     [Pa]
  /// The paper's 6 → 6 → 6 → 3 map of sorted stretches becomes a 6 → 6 → 6 → 1 map shared by
  /// the three directions. Isotropic by construction (as RbfCorrection's h(y_k)): N(Pσ, Pḟ) =
  /// P N(σ, ḟ) exactly for every permutation P, and N_i = N_j exactly whenever σ_i = σ_j and
  /// ḟ_i = ḟ_j — in particular at zero rate (the elastic part), so P = U diag(P̂ + N) Vᵀ does not
  /// depend on the arbitrary U, V at repeated stretches. ∂N/∂σ is not symmetric in general.
  Stress,
  /// The learned energy of RbfCorrection::Parameters::energy_kernels, as a network:
  ///   ΔΨ(σ) = cᵀ m(p) + μ_y + s_y · MLP((x − μ_x) ⊘ s_x),   p = power_sums(σ),
  ///           x = energy_input(σ)                                                  [J/m³]
  ///   m(p)  = (p₁, p₁², p₂, p₁³, p₁p₂, p₃)   (`polynomial` c [Pa]: every isotropic
  ///           quadratic and cubic energy in e, i.e. the RBF's linear and quadratic tails)
  ///   N = ∇_σ ΔΨ,  ∂N/∂σ = ∇²_σ ΔΨ (exact, symmetric).
  /// N does not depend on the rates; the network is fitted to the teacher's N (its gradient), so
  /// the MLP carries only what the polynomial leaves. Equal stretches give exactly equal N
  /// components (N_k = Σ_j ∂ΔΨ/∂p_j · ∂p_j/∂σ_k depends on k only through e_k), and the tangent
  /// is symmetric bit for bit.
  Energy,
};
/// "stress", "energy".
std::string to_string(NnKind kind);

/// The network correction of kind `kind` (NnKind). The MLP is
///   MLP = L_K ∘ f ∘ L_{K−1} ∘ … ∘ f ∘ L_1,   L_k(a) = W_k a + b_k,  L_K: R^w → R,
/// with f the activation (`activation`, ELU by default: paper §6.2). The batch-normalisation
/// layers of training are folded into W_k, b_k (learn::fold_batch_norm), and at construction the
/// input standardisation and the output scale are folded into the first and last layer, so
/// evaluation is a plain chain of small matrix-vector products.
///
/// Evaluation is allocation-free (stack buffers; hidden widths ≤ max_width, ≤ max_hidden_layers
/// hidden layers) and thread-safe. Stress kind: the three directions run together, one lane each
/// (packed arithmetic, every weight read once), value and exact input gradient by reverse mode
/// in one pass. Energy kind: one network pass per element; ∇ΔΨ by reverse mode and ∇²ΔΨ by the
/// exact MLP identity ∇²g = Σ_layers Σ_units (∂g/∂a_r) f''(z_r) ∇z_r ∇z_rᵀ (affine layers have no
/// curvature), with ∇z_r by forward mode.
/// Smoothness: N is C¹ in (σ, ḟ) for a stress network with ELU (C⁰ with ReLU); for an energy
/// network N is C^{k−1} with f ∈ C^k, so squareplus (learn's default), softplus or tanh (C∞)
/// give a continuous tangent, ELU a tangent that jumps where a unit crosses z = 0 and ReLU a
/// tangent without the network's curvature (docs/learning.md, "Energy network").
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
    NnKind kind = NnKind::Stress;
    Activation activation = Activation::Elu;
    /// x̃ = (x − input_mean) ⊘ input_scale for the network input x (nn_input(σ, ḟ, k): 6 entries,
    /// or energy_input(σ): 3 entries); scales > 0.
    VecX input_mean = VecX::Zero(6);
    VecX input_scale = VecX::Ones(6);
    /// g = output_mean + output_scale · y [Pa], the same for all three directions; scale > 0.
    /// For the energy kind, ΔΨ's network part [J/m³].
    double output_mean = 0;
    double output_scale = 1;
    /// Energy kind: the coefficients c of m(p) (NnKind::Energy) [Pa]; must be zero otherwise.
    Eigen::Matrix<double, 6, 1> polynomial = Eigen::Matrix<double, 6, 1>::Zero();
    /// Hidden layers (followed by the activation) then the linear output layer: the first takes
    /// the inputs (6 or 3), each takes the previous layer's outputs, the last has 1 output;
    /// hidden widths 1 … max_width, at most max_hidden_layers hidden layers. At least one layer.
    std::vector<Layer> layers;
    /// The stiffness-damping correction Δα₁(σ) of paper Eq. 13, kept as the teacher's damping
    /// RBF (material::damping_part) instead of being distilled: a function of (σ, ḟ) cannot
    /// carry −Δα₁ K_e v_e's shear modes, and a network fitted to both parts at once missed the
    /// elastic part enough that its simulations diverged (docs/learning.md). Null = no damping
    /// correction. Its elastic part must be zero.
    std::shared_ptr<const RbfCorrection> damping;
    /// Energy kind: the stretches it was learned from (its teacher's); beyond them ΔΨ is
    /// continued by its second-order expansion at the edge (material/trusted_stretches.hpp).
    TrustedStretches trusted;
  };

  /// Throws InputError("nn_correction.<field>", ...) — e.g. "nn_correction.layers[1].weight" —
  /// if the layers are missing, too many, or their sizes do not chain inputs → … → 1, a hidden
  /// width exceeds max_width, a value is not finite, a scale is not positive, the standardisation
  /// has the wrong size for the kind, a stress network has a polynomial, or `damping` has an
  /// elastic part.
  explicit NnCorrection(Parameters parameters);

  std::string name() const override { return "nn"; }
  Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const override;
  void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  Vec3 correction_with_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  std::unique_ptr<Correction> clone() const override;
  bool depends_on_rates() const override { return m_p.kind == NnKind::Stress; }
  /// Δα₀ of `damping` (0 without one).
  double mass_damping() const override { return m_p.damping ? m_p.damping->mass_damping() : 0; }
  /// Δα₁(σ) of `damping` (0 without one).
  double stiffness_damping(const Vec3& stretches) const override {
    return m_p.damping ? m_p.damping->stiffness_damping(stretches) : 0;
  }

  /// Stress kind: g(x) [Pa] at one network input x (e.g. nn_input(σ, ḟ, k)) and, if `d_input`
  /// is non-null, ∂g/∂x. Throws InputError for an energy network.
  double evaluate(const NnInput& x, NnInput* d_input = nullptr) const;
  /// Energy kind: ΔΨ(σ) [J/m³] (its gradient is N). Throws InputError for a stress network.
  double elastic_energy(const Vec3& stretches) const override;
  bool has_elastic_energy() const override { return m_p.kind == NnKind::Energy; }

  const Parameters& parameters() const { return m_p; }
  int num_inputs() const { return m_p.kind == NnKind::Stress ? 6 : 3; }

  private:
  /// Stress kind: g at the inputs of the three directions (lanes 0..2 of x[i] = input i) and,
  /// if d_x is non-null, ∂g/∂x (lanes alike).
  Eigen::Array4d stress_lanes(const Eigen::Array4d* x, Eigen::Array4d* d_x) const;
  /// Stress kind: N and, if wanted, its gradients.
  Vec3 stress_correction(const Vec3& s, const Vec3& f, Mat3* d_stretches, Mat3* d_rates) const;
  /// Energy kind: ΔΨ(σ) without the continuation.
  double formula_energy(const Vec3& stretches) const;
  /// Energy kind: N = ∇ΔΨ and, if `hessian` is non-null, ∇²ΔΨ (without the continuation).
  Vec3 energy_correction(const Vec3& s, Mat3* hessian) const;
  /// Energy kind: ∇_x g of the MLP part at x = energy_input(σ) and, if `hessian_x` is
  /// non-null, ∇²_x g (any architecture; the common ones run fixed-size kernels instead).
  Vec3 energy_network_gradient(const Vec3& x, Mat3* hessian_x) const;
  /// Energy kind: the polynomial added to the MLP's p-derivatives, then the chain rule to σ
  /// (e = σ − 1): N and, if `hessian` is non-null, ∇²ΔΨ (from `hessian_p`, then not null).
  Vec3 energy_chain(
      const Vec3& e, const Vec3& p, Vec3 grad_p, const Mat3* hessian_p, Mat3* hessian) const;

  Parameters m_p;
  ClampEnds m_ends; ///< what the smooth forms keep beyond the trusted stretches
  /// The layers with the standardisation folded in: layer k's weights (row-major, out × in) at
  /// m_flat[m_offset[k]], its biases right after. m_width[k] = layer k's input count,
  /// m_width[num_layers] = 1.
  std::vector<double> m_flat;
  std::array<int, max_hidden_layers + 2> m_offset {}, m_width {};
  int m_layers = 0;
  /// 6 or 8 for two hidden layers of that width (fixed-size kernels), else 0.
  int m_fixed_width = 0;
  /// Energy kind with m_fixed_width > 0: the folded layers in the fixed-size kernel's layout
  /// (column-major W₁, b₁, W₂, W₂ᵀ, b₂, w₃; see energy_two_layers in the .cpp).
  std::vector<double> m_energy_kernel;
};

} // namespace elastolearn::material
