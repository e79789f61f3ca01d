#pragma once
/// \file One Newton solver with backtracking line search, shared by the dynamic step and the
/// static equilibrium solve. The Jacobian is the projected (PSD) one. With an energy (statics of
/// hyperelastic models) the step is an Armijo backtracking line search on it; without one
/// (dynamics with damping or a correction) the full step is taken unless the state turns
/// non-finite or the residual grows more than 1000-fold. After a strongly contracting iteration
/// the Jacobian may be reused (NewtonOptions::jacobian_reuse_contraction).
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/system_matrix.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <functional>
#include <string>

namespace elastolearn::sim {

struct NewtonOptions {
  double relative_tolerance = 1e-6; ///< stop when ‖g‖ ≤ tol · ‖g₀‖ …
  double absolute_tolerance = 0; ///< … or ‖g‖ ≤ this [N] (0: chosen by the caller's scale)
  int max_iterations = 50;
  /// A solve whose residual has not gone below its lowest value so far for this many iterations
  /// stops as stalled (0: never): Newton then cycles instead of converging, and the caller's
  /// rescue (exact tangent, substeps) is where a solution comes from. Converging solves lower
  /// their residual every iteration or two, so this ends only solves that would reach
  /// max_iterations without converging.
  int stall_iterations = 20;
  int max_line_search = 12; ///< step halvings
  /// Jacobian reuse (a chord step): after an iteration that shrank ‖g‖ at least this many times,
  /// the next one solves with the same Jacobian and factorisation instead of re-assembling at
  /// the new iterate; an iteration that contracts less makes the next one assemble afresh.
  /// Within a time step Newton's first full step usually leaves ~1e-3 of the residual, where
  /// the Jacobian has barely changed: reuse saves an assembly and a factorisation per step at
  /// the same convergence criterion. 0 turns reuse off (every iteration assembles).
  double jacobian_reuse_contraction = 10;
  /// Time steps only (Simulator::step): a step whose Newton solve fails is retried as 2, 4, …,
  /// 2^max_step_halvings substeps before the step counts as failed. 0: no retry.
  int max_step_halvings = 3;
  /// Time steps only (Simulator::step): Newton starts each step from the velocities extrapolated
  /// at constant acceleration, v + (v − v_before), when the previous step had the same length,
  /// instead of from v. In smooth motion that start is O(h²a') from the solution rather than
  /// O(h a), so a step needs fewer iterations; the converged step is the same to the tolerance.
  /// Off by default: learning's results hang on tolerance-level differences of its simulations
  /// and its forward fit is paced by the sensitivities, not the steps (docs/design_notes.md).
  bool extrapolate_velocity = false;
  /// Simulator solves (time steps, static load steps): a solve that fails with the PSD-projected
  /// tangent is retried with the exact one, before any substep: from where it stopped if it got
  /// closer to the solution, then from its start.
  bool retry_exact_tangent = true;
  /// Throws InputError naming the offending option.
  void validate() const;
};

/// Accumulated wall time of the stages of Newton solves [s].
struct SolverTimings {
  double assembly = 0;
  double factorization = 0;
  double solve = 0;
  SolverTimings& operator+=(const SolverTimings& o);
};

struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  int jacobians = 0; ///< Jacobian assemblies (iterations minus reuses)
  int linear_iterations = 0;
  double initial_residual = 0;
  double residual = 0;
  std::string message; ///< why it stopped when not converged
  /// Equal substeps the time step took (Simulator::step): 1 unless the whole step failed and a
  /// split of it converged.
  int substeps = 1;
  /// Adds another solve's iterations, Jacobians, linear iterations and timings to this one's.
  void add_work(const NewtonReport& other);
  SolverTimings timings;
};

/// The nonlinear system g(u) = 0 over the free dofs.
struct NewtonProblem {
  /// g(u).
  std::function<void(const VecX& u, VecX& g)> residual;
  /// The (PSD) Jacobian at u, written into A (zeroed by the callee). Always called right after
  /// `residual` at the same u, so terms may reuse work cached by the residual evaluation.
  std::function<void(const VecX& u, fem::SystemMatrix& A)> jacobian;
  /// Optional energy E(u) with ∇E = g, used as the line-search merit function.
  std::function<double(const VecX& u)> energy;
  /// Optional: initial guess for the first Newton increment's linear solve (iterative solvers),
  /// overwritten with that increment. Time stepping passes the previous step's, which smooth
  /// motion makes nearly equal; it changes no convergence criterion, only the CG start.
  VecX* first_increment = nullptr;
  /// The start is a prediction (Simulator's extrapolated velocities): take at least one
  /// iteration even if its residual already meets the tolerance, which an absolute tolerance
  /// loose for a small motion can allow (the prediction alone is an explicit step).
  bool start_is_prediction = false;
};

/// Solve g(u) = 0 starting from u. The solver's symbolic analysis must already be done on A's
/// pattern. Never throws on divergence: non-finite values or no convergence give a report
/// with `converged == false` and a message.
NewtonReport newton_solve(const NewtonProblem& problem, VecX& u, fem::SystemMatrix& A,
    LinearSolver& solver, const NewtonOptions& options);

} // namespace elastolearn::sim
