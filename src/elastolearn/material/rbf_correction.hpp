#pragma once
/// \file The radial-basis-function material correction of paper 000 (Eq. 1, §6.1 Eqs. 10 and 13):
/// an isotropic elastic RBF in the principal stretches plus a stretch-dependent correction Δα₁
/// of the Rayleigh stiffness-damping coefficient. Rationale and conventions: docs/learning.md.
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/energy_kernel_copies.hpp>
#include <elastolearn/material/trusted_stretches.hpp>

#include <array>
#include <cmath>
#include <limits>

namespace elastolearn::material {

/// RBF kernel φ(r) = √(r² + ε²) [-] of the stretch distance r = ‖y − c‖. ε = 0 is the
/// polyharmonic kernel ‖y − c‖ of paper Eq. (10); ε > 0 smooths its kink at r = 0 over a
/// stretch distance ε, so that N and its gradient are continuous everywhere.
inline double rbf_kernel(double squared_distance, double epsilon) {
  return std::sqrt(squared_distance + epsilon * epsilon);
}

/// The view of the stretches seen by principal direction k: y_k = (σ_k, max(σ_a, σ_b),
/// min(σ_a, σ_b)) with a, b the other two directions. y_k is unchanged by swapping a and b.
Vec3 stretch_view(const Vec3& stretches, int k);
/// The stretch indices of stretch_view: y_k = (σ[i₀], σ[i₁], σ[i₂]) for i = stretch_view_indices(σ,
/// k).
std::array<int, 3> stretch_view_indices(const Vec3& stretches, int k);

/// The quadratic tail's basis at a stretch view y: t(y) = (e², e s, s², p) with e = y₁ − 1,
/// s = y₂ + y₃ − 2 and p = (y₂ − 1)(y₃ − 1), which span the quadratics in y − 1 symmetric in
/// y₂, y₃. Zero with zero gradient at rest.
Eigen::Vector4d quadratic_tail_basis(const Vec3& y);

/// The neo-Hookean tail's basis at a stretch view y: g(y) = (y₁ + 1/y₁ − 2,
/// ln(y₁y₂y₃)/y₁ − (y₁ + y₂ + y₃ − 3)), zero with zero gradient at rest. Neo-Hookean minus
/// corotated principal stress with the same Lamé parameters is exactly −μ g₁ + λ g₂ (the
/// corotated P̂_k = 2μ(σ_k − 1) + λ Σ(σ − 1), the neo-Hookean μ(σ_k − 1/σ_k) + λ ln J/σ_k), and
/// g₁ → ∞, g₂ → −∞ under strong compression: the barrier that the kernels and polynomial tails
/// cannot extrapolate. Stretches are floored at 10⁻³ (inverted elements) to stay finite.
/// `d_y`, if not null, receives ∂g_i/∂y as its rows.
Eigen::Vector2d neo_hookean_tail_basis(const Vec3& y, Eigen::Matrix<double, 2, 3>* d_y = nullptr);

/// The six permutations of three indices: P_π σ = (σ[π₀], σ[π₁], σ[π₂]), in the order every
/// energy-kernel sum runs over them.
inline constexpr std::array<std::array<int, 3>, 6> kStretchPermutations
    = { { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } } };

/// The energy kernel of centre c: S(σ) = Σ_π φ(‖P_π σ − c‖) over the six permutations P_π of
/// the stretches, φ = rbf_kernel. S is a smooth symmetric function of σ (for ε > 0), so its
/// gradient is a principal stress that is continuous in F (equal components at equal stretches)
/// and its Hessian is symmetric. Returns ∇S(σ); `hessian`, if not null, receives ∇²S(σ).
/// Allocation-free.
Vec3 energy_kernel_gradient(
    const Vec3& stretches, const Vec3& centre, double epsilon, Mat3* hessian = nullptr);
/// S(σ) itself (for checks: its gradient is energy_kernel_gradient).
double energy_kernel(const Vec3& stretches, const Vec3& centre, double epsilon);

/// The quadratic tails qᵀ t(y_k) that are the gradient of an isotropic cubic energy in
/// e = σ − 1: exactly those with q₁ = 2 q₂ (0-based), spanned by ∇(Σe)³ ↔ (3, 6, 3, 0),
/// ∇(Σe)(Σe²) ↔ (3, 2, 1, −2) and ∇Σe³ ↔ (3, 0, 0, 0).
inline bool is_energy_quadratic_tail(const Eigen::Vector4d& q) {
  return std::abs(q[1] - 2 * q[2]) <= 1e-9 * (std::abs(q[1]) + 2 * std::abs(q[2]));
}

/// The learned correction, for centres c_i (i = 1..m) in the space of stretch views and
/// φ_i(y) = φ(‖y − c_i‖):
///   N_k(σ)  = h(y_k)                                                                   [Pa]
///   h(y)    = Σ_i w_i φ_i(y) + a (y₁ − 1) + b (y₂ + y₃ − 2) + c + qᵀ t(y) + rᵀ g(y)     (Eq. 10)
///   Δα₁(σ)  = max(f, Σ_i v_i φ_i(s) + a_dᵀ (s − 1) + a₀ + Σ_k d_k (s_k − 1)²),  s = sort↓ σ   [s]
///   (Eq. 13)
/// One scalar function h serves all three principal directions, each seeing the stretches from
/// its own side. This makes N isotropic by construction: N(Pσ) = P N(σ) for every permutation P
/// and, crucially, N_i = N_j whenever σ_i = σ_j, so that P = U diag(P̂ + N) Vᵀ is a continuous
/// function of F even where the SVD's U, V are not unique (a general R³ → R³ map of sorted
/// stretches is not, and its stress jumps at repeated stretches, e.g. at rest). The linear tail
/// a, b, c spans exactly the isotropic linear corrections 2Δμ(σ−1) + Δλ tr(σ−1)
/// (a = 2Δμ + Δλ, b = Δλ) plus a pressure c. The optional quadratic tail qᵀ t(y)
/// (quadratic_tail_basis) spans every isotropic quadratic correction: the leading difference
/// between two hyperelastic models (e.g. StVK or neo-Hookean against corotated) at moderate
/// strain, which it extrapolates beyond the stretches seen in training, where the kernels'
/// linear growth cannot. The optional neo-Hookean tail rᵀ g(y) (neo_hookean_tail_basis) spans
/// the difference between the neo-Hookean and the corotated model, barrier included, so that
/// strong compression beyond the training's is extrapolated the way hyperelastic models behave.
/// Δα₁ is the stiffness-damping correction (Correction::stiffness_damping): the element's
/// Rayleigh damping force becomes −α₁ K_e v_e − Δα₁ K_e^nom v_e, K_e the corrected and K_e^nom
/// the nominal model's stiffness, as in paper Eq. (13) (fem::ElasticForce). A positive Δα₁ adds
/// damping; the floor f (damping_floor) bounds how much it may remove (fem::ElasticForce also keeps
/// α₁ + Δα₁ ≥ 0). N does not depend on the stretch rates. `correction`, `correction_gradient` and
/// `stiffness_damping` are exact (subgradients at ties of max/min and, for ε = 0, at a centre),
/// allocation-free and thread-safe.
class RbfCorrection final : public Correction {
  public:
  using Centres = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  struct Parameters {
    Centres centres; ///< m × 3 centres c_i [-] (m ≥ 0), in stretch-view space
    VecX weights; ///< m elastic weights w_i [Pa]
    double own_slope = 0; ///< a [Pa]
    double other_slope = 0; ///< b [Pa]
    double constant = 0; ///< c [Pa]
    Eigen::Vector4d quadratic = Eigen::Vector4d::Zero(); ///< q [Pa] (see quadratic_tail_basis)
    Eigen::Vector2d neo_hookean = Eigen::Vector2d::Zero(); ///< r [Pa] (see neo_hookean_tail_basis)
    VecX damping_weights; ///< m damping weights v_i [s], or empty for no damping RBF
    /// a_d [s]: Δα₁'s slope along each sorted stretch s₁ ≥ s₂ ≥ s₃. A linear function of the
    /// sorted stretches is symmetric (isotropic) like the kernels, and spans damping that grows
    /// with the largest stretch only, which a slope along the trace Σσ − 3 (all three equal)
    /// cannot: in bending, σ₁ − 1 is of one size on both sides while the trace nearly vanishes.
    Vec3 damping_slopes = Vec3::Zero();
    double damping_constant = 0; ///< a₀ [s]
    /// d [s]: Δα₁'s curvature along each sorted stretch, Σ_k d_k (s_k − 1)². Damping that grows
    /// (or saturates) with strain is convex (concave) in it; the kernels grow only linearly away
    /// from their centres, so beyond the training's stretches only this term carries the curvature.
    Vec3 damping_quadratic = Vec3::Zero();
    /// Δα₁ is clamped below at this value [s] when evaluated: set it to −α₁ of the nominal
    /// model so that the total stiffness damping never turns negative (energy would grow).
    double damping_floor = -std::numeric_limits<double>::infinity();
    /// Δα₀ [1/s] (Correction::mass_damping): a constant change of the nominal's mass damping.
    double mass_damping = 0;
    double epsilon = 1e-3; ///< kernel smoothing ε [-] (≥ 0)
    /// The kernels as an energy (energy_kernel_gradient): N = ∇_σ ΔΨ with
    /// ΔΨ = Σ_i w_i S_i(σ) + the tails' energies, instead of N_k = Σ_i w_i φ_i(y_k). Then ∂N/∂σ is
    /// symmetric, the corrected material is hyperelastic (elastic_energy) and its tangent can be
    /// projected like the nominal's: Newton minimises an incremental potential again. Requires
    /// the quadratic tail in the energy subspace (is_energy_quadratic_tail); the linear and
    /// neo-Hookean tails are gradients already.
    bool energy_kernels = false;
    /// The stretches the correction was learned from (energy kernels only): beyond them ΔΨ is
    /// continued by its second-order expansion at the edge (material/trusted_stretches.hpp). The
    /// default (−∞, ∞) evaluates ΔΨ everywhere.
    TrustedStretches trusted;
  };

  /// Throws InputError("rbf_correction.<field>", ...) if sizes disagree (weights ≠ m entries,
  /// damping weights neither empty nor m) or a value is not finite or ε < 0.
  explicit RbfCorrection(Parameters parameters);

  std::string name() const override { return "rbf"; }
  Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const override;
  Vec3 correction_with_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  std::unique_ptr<Correction> clone() const override;

  /// Δα₁(σ) (its gradient is not needed: the Jacobian treats α₁ as constant, as for Rayleigh).
  double stiffness_damping(const Vec3& stretches) const override;
  double mass_damping() const override { return m_p.mass_damping; }
  bool depends_on_rates() const override { return false; }

  /// N(σ) [Pa], the same as correction(stretches, ·).
  Vec3 elastic_correction(const Vec3& stretches) const;
  /// ΔΨ(σ) [J/m³] up to a constant, whose gradient is N; only for energy_kernels (throws
  /// InputError otherwise).
  double elastic_energy(const Vec3& stretches) const override;
  bool has_elastic_energy() const override { return m_p.energy_kernels; }
  /// True if Δα₁ is not identically zero or Δα₀ ≠ 0.
  bool has_damping() const;
  /// True if N is not identically zero (a weight, slope, constant, quadratic or neo-Hookean term ≠
  /// 0).
  bool has_elastic_part() const;
  int num_centres() const { return static_cast<int>(m_p.centres.rows()); }
  const Parameters& parameters() const { return m_p; }

  private:
  /// N at σ and, if d_stretches is non-null, ∂N/∂σ, without the continuation.
  Vec3 formula(const Vec3& stretches, Mat3* d_stretches) const;
  /// ΔΨ(σ) without the continuation (energy kernels).
  double formula_energy(const Vec3& stretches) const;
  /// The tails' part of h(y) (all but the kernels) and, if d_y is non-null, its ∂/∂y.
  double elastic_tail(const Vec3& y, Vec3* d_y) const;
  /// h(y_k) of the three views y_k = column k of `y` and, if d_y is non-null, column k of *d_y =
  /// ∂h/∂y at y_k; with energy_kernels the kernels are left out (m_energy_kernels adds them).
  Vec3 elastic_views(const Mat3& y, Mat3* d_y) const;
  Parameters m_p;
  /// The energy kernels, packed: Σ_i w_i ∇S_i(σ) is m_energy_kernels.gradient_sum(σ). Empty for
  /// stress kernels.
  EnergyKernelCopies m_energy_kernels;
  /// The damping kernels: centres and damping weights in structure-of-arrays form, padded to a
  /// multiple of 4 (zero weight) for packed evaluation; empty without damping weights.
  Eigen::ArrayXd m_damping_x, m_damping_y, m_damping_z, m_damping_w;
  ClampEnds m_ends; ///< what the smooth forms keep beyond the trusted stretches
};

/// (1 − t) a + t b: one correction whose N and Δα₁ (above its floor) are that blend of a's and
/// b's, with both sets of centres (a centre in both kept once, with the summed weights); b = null
/// is the zero correction. For a damped update of a correction that overshoots. Throws
/// InputError("rbf_correction.epsilon", ...) if a and b use different kernel smoothing; the
/// floor is a's.
RbfCorrection blend(const RbfCorrection& a, const RbfCorrection* b, double t);

/// c's damping correction Δα₁ alone (same centres, ε, damping terms and floor; N = 0).
RbfCorrection damping_part(const RbfCorrection& c);

} // namespace elastolearn::material
