#pragma once
/// \file Fitting a correction's unknowns to the observations through the forward simulation
/// itself: Levenberg–Marquardt on E(w) = Σ_t Σ_{observed j seen at t} ‖x_t,j(w) − o_t,j‖², with the
/// trajectory's sensitivities S_t = ∂x_t/∂w from differentiating the backward-Euler steps
///   (M/h² + K_t + D_t/h) S_t = (2M/h² + D_t/h) S_{t−1} − (M/h²) S_{t−2} + ∂f_t/∂w
/// (K ≈ −∂f/∂x, D ≈ −∂f/∂v at the converged step, the simulator's PSD-projected Jacobians;
/// ∂f/∂w is CorrectionForceJacobian, since the force is linear in the unknowns; a static
/// initial state adds K_0 S_0 = ∂f_0/∂w).
/// Unlike the space-time stages, the unobserved interior here always moves with the corrected
/// material, so the fit cannot lock it at the current model's equilibrium (docs/learning.md,
/// "Forward fit"). Each iteration costs one forward simulation plus, per frame, one extra
/// factorisation and a solve with one right-hand side per unknown.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/correction_force.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <functional>
#include <span>
#include <string>
#include <vector>

namespace elastolearn::learn {

/// One forward simulation with a correction, its error at the observed vertices and, if asked,
/// the Gauss–Newton normal equations of E at its unknowns.
struct ForwardSensitivityPass {
  bool completed = false;
  /// Not simulated: the correction is unstable at ForwardFitOptions::stability_stretches.
  bool unstable = false;
  std::string message; ///< why the simulation stopped, if it did
  ErrorSummary error; ///< at the observed vertices, all frames [m]
  double squared_error = 0; ///< E [m²]
  MatX normal; ///< Σ_t (P S_t)ᵀ (P S_t), P the observed free dofs
  VecX gradient; ///< Σ_t (P S_t)ᵀ (P x_t − o_t) (½ ∇E)
  double seconds = 0;
};

/// Which sensitivities a pass computes.
enum class Sensitivities {
  none, ///< the simulation and its error only
  projected, ///< with the simulator's PSD-projected step Jacobian (approximate where it is active)
  exact, ///< with the exact step Jacobian (exact derivatives, up to the Rayleigh term's ∂K/∂x)
};

/// Simulate `scene` (the nominal model, no correction attached) with design.correction(unknowns)
/// and compare with `observed` (T + 1 frames, validated by the caller). `mesh` is the
/// reconstruction mesh of scene.mesh with the nominal material.
ForwardSensitivityPass simulate_with_sensitivities(const sim::Scene& scene,
    const observe::Observation& observed, const ReconstructionMesh& mesh, const RbfDesign& design,
    const VecX& unknowns, Sensitivities sensitivities, const ProgressCallback& progress = {});

/// The same pass over several motions (a training set) with the same unknowns: E and its normal
/// equations are the sums over motions, `error` the statistics over all their observations
/// (combined_error) and `seconds` the sum. `meshes[i]` is the reconstruction mesh of
/// motions[i].scene. The pass stops at the first motion whose simulation diverges (with two or
/// more motions its message names the motion). One motion gives exactly its own pass.
/// Throws InputError if the spans differ in length or are empty.
ForwardSensitivityPass simulate_with_sensitivities(std::span<const Motion> motions,
    std::span<const ReconstructionMesh> meshes, const RbfDesign& design, const VecX& unknowns,
    Sensitivities sensitivities, const ProgressCallback& progress = {});

/// A trial step whose material is unstable at ForwardFitOptions::stability_stretches is halved up
/// to this many times (to 1/16 of its length) before it is rejected unsimulated.
inline constexpr int kStabilityStepHalvings = 4;

struct ForwardFitOptions {
  int max_iterations = 0; ///< trial steps (one forward simulation each) after the start
  /// Stop after an accepted step that lowers the objective by less than this fraction of its
  /// excess over the noise's expected share (`noise`; 0: take all max_iterations trial steps).
  /// Once the correction's capacity is spent, further steps cost a simulation each and change
  /// little.
  double function_tolerance = 0;
  /// σ of the observations [m] per coordinate (≥ 0; the recipe's noise estimate): the objective's
  /// floor is 3σ² per observed vertex-frame, which no correction can fit. Measured against the
  /// whole objective instead, a step on noisy data looks small however much of the learnable
  /// error it removes: on the quick dragon at σ = 0.1 % of the size the fitted nominal's
  /// training error is 99 % noise, and the fit stopped after its first accepted step.
  double noise = 0;
  /// Initial Levenberg–Marquardt damping μ on the Jacobi-scaled normal equations; ÷3 after an
  /// accepted step, ×10 after a rejected one.
  double damping = 1e-2;
  /// The step Jacobian of the sensitivities. Projected (the simulator's) by default: with the
  /// exact one, steps the projected one takes on the sphere-compression case are rejected and
  /// the fit stalls (docs/learning.md, "Forward fit"); the exact one is the derivative the tests
  /// check.
  Sensitivities sensitivities = Sensitivities::projected;
  /// Weight ρ_d of a Tikhonov prior on the damping unknowns (Δα₁): the fit minimises
  /// E(w) + ρ_d Σ_{i damping} (s_i w_i)², s_i = √(JᵀJ)_ii of the current accepted pass, so ρ_d is
  /// dimensionless like μ. Observations of a few motions constrain Δα₁ only at the stretches
  /// they reach, and an unconstrained Δα₁ extrapolates badly: the full-size sphere-compression
  /// case's test simulation (with the neo-Hookean tail) diverges without the prior and tests
  /// below the nominal with ρ_d = 1 (docs/learning.md, "Forward fit"). 0 turns the prior off.
  double damping_prior = 0;
  /// Weight ρ_e of the same prior on the elastic unknowns (N's kernels and tail): for a nominal
  /// whose elasticity is known to be right, so that only the damping is learned (ρ_e = 10⁶). A
  /// motion whose velocity stays nearly proportional to its displacement cannot tell extra
  /// stiffness damping from an elastic softening, and a free fit may split the two wrongly
  /// (docs/learning.md, "Forward fit"). 0 turns the prior off.
  double elastic_prior = 0;
  /// Principal stretches (N × 3) where every trial's material must be stable
  /// (material_stability.hpp); a trial that is not is shortened (kStabilityStepHalvings), and
  /// rejected without being simulated if no shorter step is stable (its simulation would diverge
  /// or stall). Empty: no check. In the loop (LearningOptions::forward_fit) these are kept and
  /// the samples of the best correction's own runs added (the recipe sets the stretches its
  /// validation requires stability at).
  MatX stability_stretches;
  /// A step none of whose fractions is stable is solved again subject to stability cuts at
  /// stability_stretches (stability_cuts.hpp) instead of being rejected unsimulated: it keeps
  /// the step's direction wherever the data ask and turns only where a state would lose its
  /// stiffness. The recipe's (RecipeOptions); off by default, as before the cuts.
  bool stability_cuts = false;
  /// Throws InputError("forward_fit.<field>", ...) for an out-of-range field.
  void validate() const;
};

struct ForwardFitResult {
  VecX unknowns; ///< the best found (the start if no step improved)
  std::vector<double> rms_history; ///< RMS error of each simulation, the start first (−1: diverged)
  int accepted = 0; ///< steps that lowered the error
  /// An accepted step lowered the objective by less than options.function_tolerance: the fit
  /// stopped there, before max_iterations.
  bool converged = false;
  double seconds = 0;
};

/// Called after each trial step with its pass, whether it was accepted, the unknowns kept and
/// the damping μ for the next step; returns false to stop the fit there.
using ForwardFitStepCallback = std::function<bool(
    const ForwardSensitivityPass& trial, bool accepted, const VecX& kept, double damping)>;

/// Levenberg–Marquardt from `start` (unknowns in design's layout), with options.damping as the
/// first μ, on E summed over `motions` (each with its reconstruction mesh `meshes[i]`; the
/// motions share the nominal material, their meshes may differ). A trial is rejected if any
/// motion's simulation diverges. Throws InputError for invalid options, spans that differ in
/// length or are empty, or if the start's simulation diverges.
ForwardFitResult fit_to_observations(std::span<const Motion> motions,
    std::span<const ReconstructionMesh> meshes, const RbfDesign& design, const VecX& start,
    const ForwardFitOptions& options, const ProgressCallback& progress = {},
    const ForwardFitStepCallback& on_step = {});

/// One motion: `scene` (the nominal model) against `observed`, `mesh` its reconstruction mesh.
ForwardFitResult fit_to_observations(const sim::Scene& scene, const observe::Observation& observed,
    const ReconstructionMesh& mesh, const RbfDesign& design, const VecX& start,
    const ForwardFitOptions& options, const ProgressCallback& progress = {},
    const ForwardFitStepCallback& on_step = {});

} // namespace elastolearn::learn
