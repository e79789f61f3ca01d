#pragma once
/// \file Least squares for a correction that must stay stable (issue 19, "stable corrections"):
/// the fit is solved subject to the linear conditions that keep the corrected material's
/// stiffness positive at the stability samples, instead of shrinking a fitted correction until it
/// is stable (which gives up the fit everywhere for a few states no data reached).
///
/// Why linear: with the correction's unknowns x (RbfDesign), N(σ) = A(σ) x_e, so along a fixed
/// direction d the stretch block's stiffness dᵀ(∂P̂/∂σ + ∂N/∂σ)d and each twist eigenvalue
/// (P̂ᵢ + Nᵢ − P̂ⱼ − Nⱼ)/(σᵢ − σⱼ) are affine in x. Where a solution is unstable at a sample, the
/// condition that its softest direction keep a fraction of the nominal's stiffness there is a cut
/// gᵀx ≥ h; the fit is solved again with every cut so far, until no sample is unstable (cutting
/// planes: each cut is a true condition of stability, so keeping them all is conservative).
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/material/elastic_model.hpp>

namespace elastolearn::learn {

/// Linear conditions G x ≥ h on a fit's unknowns.
struct LinearInequalities {
  MatX rows; ///< G, k × unknowns
  VecX bounds; ///< h, k
  Eigen::Index size() const { return rows.rows(); }
  /// Appends `more` (same number of unknowns, or this one empty).
  void append(const LinearInequalities& more);
};

/// The fraction of the nominal's stiffness a cut keeps along the direction it constrains. Above
/// 0 so that the solution is stable with a margin instead of on the edge of instability, where
/// the next solve's other samples would fail first; small so that the data, not the cut, decide
/// the correction wherever they can.
inline constexpr double kCutKeptStiffness = 0.1;

/// At every row σ of `samples` where nominal + design.correction(x) is unstable (the check of
/// material_stability: the stretch block's smallest eigenvalue or a twist eigenvalue < 0), the
/// cuts that ask its stretch block along the eigenvector d of that eigenvalue, and each negative
/// twist, to keep `kept` of the nominal's: dᵀ(∂N/∂σ)d ≥ (kept − 1) dᵀ(∂P̂/∂σ)d, and the twist's
/// correction part ≥ (kept − 1) times the nominal's twist. Rows are over all design unknowns
/// (zero beyond the elastic ones) and scaled to unit length. At most `max_cuts`, the most unstable
/// samples first. Beyond the trusted stretches the rows are the design's continuation (the edge's
/// Hessian unbounded), which the correction's bound only stiffens.
LinearInequalities stability_cuts(const RbfDesign& design, const material::ElasticModel& nominal,
    ConstRef<VecX> x, ConstRef<MatX> samples, double kept = kCutKeptStiffness,
    Eigen::Index max_cuts = 256);

/// min ½ xᵀQx − rhsᵀx subject to G x ≥ h, Q the factorised regularised normal matrix: x =
/// x₀ + Q⁻¹Gᵀλ with x₀ = Q⁻¹ rhs and λ ≥ 0 solving the dual (a linear complementarity problem
/// in the k multipliers: λ ≥ 0, Mλ − c ≥ 0, λᵀ(Mλ − c) = 0 with M = GQ⁻¹Gᵀ, c = h − Gx₀), by
/// projected Gauss–Seidel to a residual violation of 10⁻⁹ of ‖c‖ or 2000 sweeps. Exact for
/// x₀ when it satisfies every condition (or there are none).
VecX solve_with_inequalities(const RegularisedNormalEquations& equations, ConstRef<VecX> rhs,
    const LinearInequalities& conditions);

/// What stable_least_squares did.
struct StableSolve {
  VecX x;
  Eigen::Index cuts = 0; ///< conditions the solution was held to (0: the unconstrained fit)
  int rounds = 0; ///< solves after the unconstrained one
};

/// The fit of `equations` and `rhs` (design's unknowns), cut (stability_cuts, solve_with_
/// inequalities) until nominal + design.correction(x) is stable at every row of `samples`, or
/// `max_rounds` solves with cuts; `base` is added to x for the stability check and the cuts
/// (the correction is design.correction(base + x): zero for a fit of the whole correction, the
/// current point for a step of the forward fit). The result may still be unstable after
/// max_rounds (the caller's check decides). `kept` are conditions every solve keeps besides the
/// cuts (e.g. a bound on an unknown); StableSolve::cuts counts only the cuts.
StableSolve stable_least_squares(const RegularisedNormalEquations& equations, ConstRef<VecX> rhs,
    const RbfDesign& design, const material::ElasticModel& nominal, ConstRef<MatX> samples,
    ConstRef<VecX> base, int max_rounds = 8, const LinearInequalities& kept = {});

} // namespace elastolearn::learn
