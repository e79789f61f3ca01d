#pragma once
/// \file Least-squares fit of an RbfCorrection (paper 000 §6.1, Eqs. 10–13) to samples of
/// principal stretches → principal stress correction, with Tikhonov regularisation. RbfDesign
/// fixes the unknowns' layout so that the stress reconstruction of the learning loop (Eq. 13,
/// through the nodal-force operator B) can reuse the same maps from unknowns to the elastic
/// stress and to the stiffness-damping correction Δα₁.
#include <elastolearn/material/energy_kernel_bank.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <Eigen/Cholesky>

#include <limits>

namespace elastolearn::learn {

struct RbfFitOptions {
  double epsilon = 1e-3; ///< kernel smoothing ε of material::rbf_kernel [-]
  /// Energy kernels (material::RbfCorrection::Parameters::energy_kernels): the correction is the
  /// gradient of an energy, its tangent symmetric; the quadratic tail then has 3 unknowns (the
  /// cubic energies), not 4.
  bool energy_kernels = false;
  /// How learning continues an energy correction beyond its trusted stretches
  /// (material/trusted_stretches.hpp): the edge's bounded Hessian (the recipe), or the exact
  /// smooth expansion (`learn --continuation smooth_expansion`; smooth_clamp, its uncoupled
  /// form, for comparison).
  material::Continuation continuation = material::Continuation::bounded_softening;
  bool elastic_polynomial
      = true; ///< fit the linear tail a, b (and c, see below) of the elastic part
  /// Keep the rest shape stress-free: N(1, 1, 1) = 0, as for every hyperelastic model. The
  /// kernels enter as φ_i(y) − φ_i(1) and the pressure c is not an unknown but follows from the
  /// weights (c = −Σ w_i φ_i(1)). Without it the fit may explain residual forces by a prestress
  /// at rest (the full-size sphere's first correction then has N(1) = +1.07 kPa), and an
  /// unloaded object simulated with the learned material would not stay at rest.
  bool stress_free_rest = true;
  /// Also fit the quadratic tail q (material::quadratic_tail_basis; needs elastic_polynomial).
  bool quadratic_tail = true;
  /// Also fit the neo-Hookean tail r (material::neo_hookean_tail_basis; needs elastic_polynomial).
  /// The recipe (learn::RecipeOptions) turns it on together with mass_damping where the fitted α₀
  /// is positive: alone, with α₀ held fixed, it learned worse (docs/learning.md, "Neo-Hookean
  /// tail").
  bool neo_hookean_tail = false;
  /// Fit the stiffness-damping RBF Δα₁(σ) (only the stress reconstruction can: it needs the
  /// elements' damping forces, which principal stress samples do not carry).
  bool fit_damping = true;
  bool damping_polynomial = true; ///< fit the linear tail a_dᵀ(sort↓σ − 1) + a₀ of Δα₁
  /// Also fit Δα₁'s quadratic tail Σ_k d_k (s_k − 1)² (needs damping_polynomial).
  bool damping_quadratic_tail = false;
  /// Tikhonov weight λ ≥ 0 on the Jacobi-scaled unknowns: (S⁻¹JᵀJS⁻¹ + λI) S x = S⁻¹Jᵀy with
  /// S = √diag(JᵀJ), so λ is dimensionless and independent of the units of each unknown.
  double regularization = 1e-9;
  /// The same for the damping unknowns. Reconstructing the bar-damping case's Δα₁(σ) from its
  /// true trajectory: 1e-3 biased Δα₁ at σ₁ = 1.05 by −24 % (0.076 for 0.1 s), 1e-9 recovered
  /// 0.1005 (force misfit 7 % → 1.3 % of the target); 1e-6 keeps a little damping of noise.
  double damping_regularization = 1e-6;
  /// Weight λ ≥ 0 of the smoothness penalty (RbfDesign::smoothness_penalty): the native-space
  /// seminorm of the kernel part, the smoothing-spline regulariser of a kernel fit. Where the
  /// samples do not pin the correction down, it keeps the function from taking whatever shape
  /// the centres give it. λ is relative to the data: the penalty's trace over each block of
  /// kernel weights is λ × the normal matrix's, so it does not depend on units or sample count.
  double smoothness = 0;
  /// Floor of Δα₁ written into the correction (material::RbfCorrection::damping_floor) [s].
  double damping_floor = -std::numeric_limits<double>::infinity();
  /// Also fit Δα₀ (material::Correction::mass_damping), one unknown after the others: a constant
  /// change of the nominal's mass damping, learned with the correction. Only fits that see nodal
  /// forces or motions (CorrectionForceJacobian: the loop's reconstruction, the forward fit) can;
  /// stress samples carry no mass damping, and fit_rbf_correction leaves it 0.
  bool mass_damping = false;
  /// Throws InputError("rbf_fit.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The unknowns of an RBF correction with given centres, and the linear maps from them to N and
/// Δα₁. Unknowns x = [x_e; x_d] with x_e = [w (m); a, b, c, q, r (with the elastic tail; c only
/// without stress_free_rest, q only with quadratic_tail, r only with neo_hookean_tail)] and x_d =
/// [v (m); a_d (3), a₀ (with the damping tail); d (3) (with damping_quadratic_tail)] (only when
/// fit_damping), then Δα₀ (only with mass_damping), in the notation of material::RbfCorrection
/// (before Δα₁'s floor):
///   N(σ) = A(σ) x_e,   row k of A = [φ_i(y_k) − r_i …, y_k1 − 1, y_k2 + y_k3 − 2, 1, t(y_k)ᵀ,
///   g(y_k)ᵀ], Δα₁(σ) = d(σ) x_d, d = [φ_i(s) …, (s − 1)ᵀ, 1, ((s − 1)²)ᵀ], s = sort↓ σ,
/// with r_i = φ_i(1, 1, 1) under stress_free_rest (else 0).
class RbfDesign {
  public:
  using OutputMatrix = Eigen::Matrix<double, 3, Eigen::Dynamic>;
  /// `centres` m × 3 (m ≥ 1, finite). With energy kernels, `trusted` is the corrections' trusted
  /// stretches (material/trusted_stretches.hpp), and A(σ) continues beyond them as the
  /// correction does. The smooth forms (smooth_clamp, smooth_expansion) are linear in x, so N = A x
  /// everywhere (and Δα₁ = d x, read at φ(σ) too), except beyond an end whose stiffness is at its
  /// floor or, for smooth_expansion, whose Hessians are bounded (the forward fit's steps are
  /// accepted on simulated errors). The expansions continue A
  /// with the edge's Hessian, A(c) + ∂A/∂σ(c)(σ − c): N = A x everywhere for edge_hessian, and for
  /// bounded_softening wherever the edge's Hessian is within the bound (elsewhere A x is its
  /// continuation with that Hessian unbounded). Throws InputError for invalid options, centres
  /// or interval.
  RbfDesign(ConstRef<MatX> centres, const RbfFitOptions& options,
      material::TrustedStretches trusted = {});
  int num_centres() const { return static_cast<int>(m_centres.rows()); }
  /// m (+ 2 or 3 with the tail, + 4 quadratic, or 3 with energy kernels, + 2 neo-Hookean)
  int elastic_unknowns() const { return m_elastic; }
  int damping_unknowns() const { return m_damping; } ///< 0, or m (+ 4 with the tail)
  /// The index of Δα₀ (the last unknown), or −1 without mass_damping.
  int mass_damping_unknown() const { return m_options.mass_damping ? m_elastic + m_damping : -1; }
  int num_unknowns() const { return m_elastic + m_damping + (m_options.mass_damping ? 1 : 0); }
  const RbfFitOptions& options() const { return m_options; }
  using OutputGradient = Eigen::Matrix<double, 9, Eigen::Dynamic>;
  /// A(σ) into `out` (3 × elastic_unknowns()), for stretches in any order. No allocation.
  void output_matrix(const Vec3& stretches, Eigen::Ref<OutputMatrix> out) const;
  /// A(σ) and its stretch derivative: row 3j + k of `gradient` (9 × elastic_unknowns()) is
  /// ∂A(k, ·)/∂σ_j, i.e. column i reshaped (column-major) is ∂N/∂σ of unknown i alone. Exact
  /// (subgradients at ties, and at a centre for ε = 0). No allocation.
  void output_matrix(const Vec3& stretches, Eigen::Ref<OutputMatrix> out,
      Eigen::Ref<OutputGradient> gradient) const;
  /// d(σ) into `out` (damping_unknowns() entries), for stretches in any order. No allocation.
  void damping_row(const Vec3& stretches, Eigen::Ref<Eigen::RowVectorXd> out) const;
  /// Tikhonov weight of each unknown (regularization, or damping_regularization).
  VecX regularization_weights() const;
  /// The smoothness penalty xᵀ R x to add to a least-squares objective whose normal matrix (JᵀJ)
  /// is `normal`, over the first normal.rows() unknowns (elastic_unknowns() or num_unknowns()).
  /// Per block of m kernel weights w (the elastic ones; Δα₁'s when `normal` covers them), the
  /// native-space seminorm −(Pw)ᵀ K_c (Pw) of Σ w_i K(·, c_i): K_c the kernel between the centres
  /// (the energy kernel, or φ(‖c_i − c_j‖) for stress kernels and Δα₁), conditionally positive
  /// definite of order 1 (multiquadric), and P = I − 11ᵀ/m removing the weights' mean, the one
  /// direction it does not see. Each block is scaled to trace λ × that block of `normal`; the
  /// tails are not penalised. Positive semidefinite; zero for λ = 0 or a single centre.
  MatX smoothness_penalty(ConstRef<MatX> normal) const;
  /// The correction whose unknowns are `x` (length num_unknowns()).
  material::RbfCorrection correction(ConstRef<VecX> x) const;
  /// The unknowns of a correction over this design's centres (inverse of `correction`). Throws
  /// InputError("rbf_fit.correction", ...) if its centres or ε differ, or it has a term this
  /// design cannot express (a tail without elastic_polynomial, damping without fit_damping, a
  /// prestress N(1) ≠ 0 under stress_free_rest).
  VecX unknowns(const material::RbfCorrection& correction) const;

  const material::TrustedStretches& trusted() const { return m_trusted; }

  private:
  /// A(σ) without the continuation.
  void formula_columns(const Vec3& stretches, Eigen::Ref<OutputMatrix> out) const;
  /// The smooth forms beyond the trusted stretches, per stretch: φ, whether it is beyond an end,
  /// that end's row, d = σ − φ and u = φ − 1'.
  struct ClampState {
    material::ClampedStretch stretch[3];
    bool beyond[3] = { false, false, false };
    int end[3] = { 0, 0, 0 };
    Vec3 distance, offset;
  };
  /// σ's ClampState, and into `a` and `b` (3 × elastic unknowns) the rows a_q (zero unless
  /// stretch q is beyond an end) and b_q of material::smoothly_clamped_correction.
  ClampState clamp_state(const Vec3& stretches, OutputMatrix& a, OutputMatrix& b) const;
  /// `out` holds A at φ(σ) and becomes the continuation's, row q φ'_q (A_q(φ) + b_q) +
  /// (1 − φ'_q) a_q.
  void clamp_rows(const ClampState& c, const OutputMatrix& a, const OutputMatrix& b,
      Eigen::Ref<OutputMatrix> out) const;
  /// Its derivative: `gradient` holds ∂A/∂φ at φ(σ) and `out` A there (before clamp_rows).
  void clamp_gradient(const ClampState& c, const OutputMatrix& a, const OutputMatrix& b,
      Eigen::Ref<const OutputMatrix> out, Eigen::Ref<OutputGradient> gradient) const;
  /// A(σ) and its derivative, without the continuation.
  void formula_matrix(const Vec3& stretches, Eigen::Ref<OutputMatrix> out,
      Eigen::Ref<OutputGradient> gradient) const;
  /// The columns that come from the stretch views: the stress kernels (not energy kernels, which
  /// each overload of output_matrix fills itself) and the tails.
  void view_columns(const Vec3& stretches, Eigen::Ref<OutputMatrix> out) const;
  material::RbfCorrection::Centres m_centres;
  /// The centres' energy kernels (energy_kernels only).
  material::EnergyKernelBank m_energy_kernels;
  RbfFitOptions m_options;
  VecX m_rest_kernels; ///< r_i = φ_i(1, 1, 1) under stress_free_rest, else 0
  /// −P K_c P of smoothness_penalty, scaled to unit trace (zero if its trace is 0), elastic and
  /// damping (empty without damping unknowns, and both empty for smoothness 0).
  MatX m_elastic_seminorm, m_damping_seminorm;
  int m_constant = -1; ///< column of the pressure c, or −1
  int m_quadratic = -1; ///< first column of q (or, with energy kernels, of its 3 energies), or −1
  int m_neo_hookean = -1; ///< first column of r, or −1
  int m_elastic = 0;
  int m_damping = 0;
  material::TrustedStretches m_trusted;
  /// The smooth forms: at TrustedStretches::end_point above (row 0) and below (row 1), row 0 of A
  /// (G, the end stress) and of ∂A/∂σ₀ (K, the end stiffness, without its floor) and ∂A/∂σ₁
  /// (L, the coupling); and ∂A(0, ·)/∂σ₁ where two stretches are beyond ends (M; rows pair_row),
  /// all without their bounds.
  Eigen::Matrix<double, 2, Eigen::Dynamic> m_end_stress, m_end_stiffness, m_end_coupling;
  Eigen::Matrix<double, 3, Eigen::Dynamic> m_pair_coupling;
  /// f of material::ClampEnds: 1 for smooth_expansion (with L and M), 0 for smooth_clamp.
  double m_follow = 0;
  /// The row of m_pair_coupling for two stretches beyond ends e and f (0 above, 1 below).
  static int pair_row(int e, int f) { return e + f; }
  /// The row of m_end_stress and m_end_stiffness for a stretch beyond an end.
  int end_row(double stretch) const { return stretch > m_trusted.max ? 0 : 1; }
};

/// Stress samples: row j is one element at one frame.
struct StressSamples {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> stretches; ///< N × 3 [-]
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> stretch_rates; ///< N × 3 [1/s]
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> targets; ///< N × 3 [Pa]
};

struct RbfFitResult {
  material::RbfCorrection correction;
  VecX unknowns; ///< x in RbfDesign's layout
  double rms_residual = 0; ///< √(mean ‖N(σ_j, ḟ_j) − y_j‖²) over the samples [Pa]
  double rms_target = 0; ///< √(mean ‖y_j‖²) [Pa]
  int samples = 0;
};

/// Minimise Σ_j ‖N(σ_j) − y_j‖² + Tikhonov (see RbfFitOptions::regularization) over the
/// elastic unknowns of `design`; its damping unknowns, if any, are left at zero (stress samples
/// say nothing about Δα₁). The stretch rates of the samples are not used. The normal equations are
/// accumulated in chunks by symmetric rank updates of the stacked output matrices, O(N u²) time and
/// O(u² + chunk·u) memory for u = num_unknowns(); solved by dense Cholesky. Throws InputError if
/// the sample arrays disagree in size, are empty or not finite, or the regularised normal matrix is
/// singular (e.g. λ = 0 with fewer independent samples than unknowns).
RbfFitResult fit_rbf_correction(const RbfDesign& design, const StressSamples& samples);

/// The stretch views (material::stretch_view) of every sample, 3N × 3 (rows 3j..3j+2 are sample
/// j's three directions): the points the RBF centres should cover, e.g. by k-means.
MatX stretch_views(ConstRef<MatX> stretches);

/// The normal matrix N (symmetric, full) with Jacobi scaling S = √diag and Tikhonov λ_i (one
/// per unknown) on the scaled unknowns, factorised once: solve(rhs) is x of
/// (S⁻¹ N S⁻¹ + diag λ) S x = S⁻¹ rhs, i.e. Q x = rhs with Q = N + S diag(λ) S. `samples` is only
/// quoted in the error. Throws InputError if the system is singular.
class RegularisedNormalEquations {
  public:
  RegularisedNormalEquations(MatX normal, ConstRef<VecX> regularization, long samples);
  /// Q⁻¹ rhs (a vector, or each column of a matrix). Throws InputError if not finite.
  MatX solve(ConstRef<MatX> rhs) const;
  Eigen::Index size() const { return m_scale.size(); }

  private:
  VecX m_scale; ///< S
  Eigen::LLT<MatX> m_llt; ///< of S⁻¹ N S⁻¹ + diag λ
};

/// RegularisedNormalEquations(normal, regularization, samples).solve(rhs).
VecX solve_regularised_normal_equations(
    MatX normal, ConstRef<VecX> rhs, ConstRef<VecX> regularization, long samples);

} // namespace elastolearn::learn
