#pragma once
/// \file Levenberg–Marquardt for least-squares fits whose evaluations are expensive and may fail
/// (whole forward simulations, which can diverge): parameter_fit and forward_fit use it, each
/// with its own damping constants. At the current point the problem gives the Gauss–Newton
/// normal equations H δ = −g (H = JᵀJ, g = Jᵀr, the cost Φ = ‖r‖², plus any prior); the driver
/// tries the damped step from them. A trial whose cost is lower is accepted and μ shrinks; one
/// whose cost is not lower, or whose evaluation fails, is rejected, μ grows and a shorter step
/// from the same equations is tried. The problem owns the point: the driver hands it steps δ and
/// tells it which trial to keep. In the style of Ceres's Solver::Options / Summary.
#include <elastolearn/core/types.hpp>
#include <elastolearn/learn/rbf_fit.hpp>
#include <elastolearn/learn/stability_cuts.hpp>

#include <functional>
#include <limits>
#include <optional>

namespace elastolearn::learn {

/// How the damping μ enters the normal equations.
enum class DampingScaling {
  /// Marquardt's (H + μ diag H) δ = −g, solved by LDLᵀ. An unknown whose H_ii is at most 10⁻¹⁴
  /// of the largest (it does not move the residuals) is held fixed, δ_i = 0; when every H_ii is
  /// zero there is no step (LevenbergMarquardtStop::degenerate).
  marquardt,
  /// Jacobi-scaled, (S⁻¹ H S⁻¹ + μ I) S δ = −S⁻¹ g with S = √diag H (1 where H_ii = 0: only μ
  /// holds that unknown), solved by Cholesky (solve_regularised_normal_equations of rbf_fit.hpp,
  /// which throws InputError if that fails).
  jacobi,
};

struct LevenbergMarquardtOptions {
  int max_iterations = 100; ///< normal equations formed at most (≥ 1)
  int max_steps = std::numeric_limits<int>::max(); ///< trial steps evaluated at most (≥ 0)
  int max_rejections = 10; ///< rejected trial steps in a row before giving up (≥ 1)
  double initial_damping = 1e-3; ///< μ of the first trial step (> 0, finite)
  DampingScaling scaling = DampingScaling::jacobi;
  double damping_decrease = 3; ///< μ ÷ this after an accepted step (≥ 1, finite) …
  double min_damping = 0; ///< … but never below this (≥ 0, finite)
  /// μ × this after a rejected step whose evaluation completed (> 1, finite).
  double damping_increase = 10;
  /// μ × this after a rejected step whose evaluation failed (> 1, finite): such a step was
  /// usually far too long, so a caller may shrink it harder.
  double failed_damping_increase = 10;
  /// Largest |δ_i| of a trial step, in the unknowns' units (> 0; ∞ = no limit): a longer step
  /// is scaled down to it, keeping its direction.
  double max_step = std::numeric_limits<double>::infinity();
  /// Stop when an accepted step lowers the cost by less than this fraction of its excess over
  /// cost_floor (≥ 0; 0 never stops).
  double function_tolerance = 0;
  /// The cost no point can be expected to go below (≥ 0, finite): for least squares on noisy
  /// data, the noise's expected share. function_tolerance measures a decrease against the cost
  /// above it, so that noise no model fits does not make every step look small; at or below
  /// the floor the tolerance never stops the solve.
  double cost_floor = 0;
  /// Throws InputError("levenberg_marquardt.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The Gauss–Newton normal equations at the problem's current point (n unknowns, n ≥ 1).
struct NormalEquations {
  MatX hessian; ///< H, n × n, symmetric positive semi-definite (JᵀJ plus any prior)
  VecX gradient; ///< g, n: the undamped step solves H δ = −g
  double cost = 0; ///< Φ at the current point: a trial is accepted if its cost is lower
  long samples = 0; ///< observations behind H, quoted in the error if the jacobi solve fails
  /// Optional (empty = unbounded): the least step of each unknown, −∞ for none. An unknown whose
  /// damped step would go below its bound is held at it and the others are solved again
  /// (marquardt: an active set; jacobi: solve_with_inequalities of stability_cuts.hpp), so a
  /// parameter resting on its bound does not take the others' steps with it (through max_step,
  /// or through a clamp after the solve). With every bound ≤ 0 (the current point within its
  /// bounds), scaling a step down keeps it within them.
  VecX lower_step;
};

/// A trial point's evaluation.
struct TrialEvaluation {
  /// False if the evaluation failed (e.g. its simulation diverged): the step is rejected.
  bool completed = false;
  /// Φ at the trial, measured as NormalEquations::cost was (ignored unless completed).
  double cost = std::numeric_limits<double>::infinity();
  /// End the solve here, without judging this trial (e.g. an interrupt was requested).
  bool stop = false;
};

/// What the driver decided about one trial step.
struct LevenbergMarquardtStep {
  int iteration = 0; ///< which normal equations it came from (1 = the first)
  bool completed = false; ///< its evaluation completed
  bool accepted = false; ///< it lowered the cost and is the current point now
  double cost = std::numeric_limits<double>::infinity(); ///< its Φ (∞ if it failed)
  /// (Φ_current − Φ_trial) / (Φ_current − cost_floor) if accepted (+∞ where Φ_current ≤ the
  /// floor), else 0
  double relative_decrease = 0;
  int rejections = 0; ///< rejected steps in a row from these equations, this one included
  bool gives_up = false; ///< the max_rejections-th rejection in a row: the solve ends after it
  double damping = 0; ///< μ for the next trial step
};

/// The problem, as callbacks around a current point that the problem keeps.
struct LevenbergMarquardtProblem {
  /// The normal equations at the current point, or nothing to end the solve there (e.g. the
  /// cost is already small enough). Required.
  std::function<std::optional<NormalEquations>()> linearize;
  /// Evaluate the trial point current + `step` (n); the current point does not move. Required.
  std::function<TrialEvaluation(const VecX& step)> evaluate;
  /// The last evaluated trial lowered the cost: make it the current point. Required.
  std::function<void()> accept;
  /// Called after each trial step (after `accept` for an accepted one); returns false to end
  /// the solve there. Optional.
  std::function<bool(const LevenbergMarquardtStep& step)> on_step;
  /// The jacobi scaling's step from its damped, factorised equations Q δ = rhs (−g) subject to
  /// `bounds` (NormalEquations::lower_step as rows δ_i ≥ lower_i; none if it is empty), e.g.
  /// with more conditions on the trial point (stable_least_squares). Optional:
  /// solve_with_inequalities(equations, rhs, bounds).
  std::function<VecX(const RegularisedNormalEquations& equations, const VecX& rhs,
      const LinearInequalities& bounds)>
      solve_step;
};

/// Why the solve ended.
enum class LevenbergMarquardtStop {
  converged, ///< an accepted step lowered the cost by less than function_tolerance
  max_iterations, ///< max_iterations normal equations were formed (each one's step accepted)
  max_steps, ///< max_steps trial steps were evaluated
  no_improving_step, ///< max_rejections trial steps in a row were rejected
  degenerate, ///< (marquardt) every diagonal entry of H is zero: no unknown moves the residuals
  stopped, ///< the problem ended it (linearize gave nothing, evaluate said stop, on_step false)
};

struct LevenbergMarquardtSummary {
  LevenbergMarquardtStop stop = LevenbergMarquardtStop::max_iterations;
  int iterations = 0; ///< normal equations formed
  int steps = 0; ///< trial steps evaluated
  int accepted = 0; ///< of those, accepted
  int rejections = 0; ///< rejected steps in a row at the end
  double relative_decrease = 0; ///< of the last accepted step (0 if none)
  double damping = 0; ///< μ at the end (what the next trial step would use)
};

/// Run Levenberg–Marquardt on `problem` from its current point. Throws InputError for invalid
/// options (and from the jacobi solve), InternalError if a required callback is missing or the
/// normal equations are empty or of mismatched sizes, and whatever the callbacks throw.
LevenbergMarquardtSummary levenberg_marquardt(
    const LevenbergMarquardtProblem& problem, const LevenbergMarquardtOptions& options);

} // namespace elastolearn::learn
