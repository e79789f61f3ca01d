#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/sim/newton.hpp>

#include <cmath>

namespace elastolearn::sim {

void NewtonOptions::validate() const {
  if (!(relative_tolerance > 0 && relative_tolerance < 1))
    throw InputError("newton.relative_tolerance",
        "must be in (0, 1), got " + std::to_string(relative_tolerance));
  if (!(absolute_tolerance >= 0))
    throw InputError("newton.absolute_tolerance", "must be >= 0");
  if (max_iterations < 1)
    throw InputError("newton.max_iterations", "must be >= 1");
  if (stall_iterations < 0)
    throw InputError("newton.stall_iterations", "must be >= 0 (0: off)");
  if (max_line_search < 0)
    throw InputError("newton.max_line_search", "must be >= 0");
  if (max_step_halvings < 0 || max_step_halvings > 10)
    throw InputError(
        "newton.max_step_halvings", "must be in [0, 10], got " + std::to_string(max_step_halvings));
  if (!(jacobian_reuse_contraction == 0 || jacobian_reuse_contraction > 1))
    throw InputError("newton.jacobian_reuse_contraction", "must be 0 (off) or > 1");
}

SolverTimings& SolverTimings::operator+=(const SolverTimings& o) {
  assembly += o.assembly;
  factorization += o.factorization;
  solve += o.solve;
  return *this;
}

void NewtonReport::add_work(const NewtonReport& other) {
  iterations += other.iterations;
  jacobians += other.jacobians;
  linear_iterations += other.linear_iterations;
  timings += other.timings;
}

NewtonReport newton_solve(const NewtonProblem& problem, VecX& u, fem::SystemMatrix& A,
    LinearSolver& solver, const NewtonOptions& options) {
  NewtonReport report;
  VecX g(u.size()), du = VecX::Zero(u.size()), u_prev(u.size());
  // Reuse the Jacobian only after a full step that contracted the residual enough.
  auto reuse_after = [&](double step, double before, double after) {
    const double c = options.jacobian_reuse_contraction;
    return c > 0 && step == 1.0 && std::isfinite(after) && after * c <= before;
  };
  auto evaluate = [&](const VecX& at) {
    const auto t0 = Clock::now();
    problem.residual(at, g);
    report.timings.assembly += seconds_since(t0);
    return g.norm();
  };
  double norm = evaluate(u);
  report.initial_residual = norm;
  bool reuse_jacobian = false; // the first iteration always assembles
  const double target
      = std::max(options.relative_tolerance * report.initial_residual, options.absolute_tolerance);
  double lowest = norm; // and the iteration that reached it
  int lowest_at = 0;
  for (;;) {
    report.residual = norm;
    if (!std::isfinite(norm)) {
      report.message = "residual is not finite";
      return report;
    }
    if (norm <= target && (report.iterations > 0 || !problem.start_is_prediction)) {
      report.converged = true;
      return report;
    }
    if (norm < lowest) {
      lowest = norm;
      lowest_at = report.iterations;
    } else if (options.stall_iterations > 0
        && report.iterations - lowest_at >= options.stall_iterations) {
      report.message = "stalled: no Newton iteration of the last "
          + std::to_string(options.stall_iterations) + " went below residual "
          + std::to_string(lowest) + " (now " + std::to_string(norm) + ", target "
          + std::to_string(target) + ")";
      return report;
    }
    if (report.iterations == options.max_iterations) {
      report.message = "no convergence in " + std::to_string(report.iterations)
          + " Newton iterations (residual " + std::to_string(norm) + ", target "
          + std::to_string(target) + ")";
      return report;
    }
    ++report.iterations;
    auto t0 = Clock::now();
    if (!reuse_jacobian) {
      problem.jacobian(u, A);
      report.timings.assembly += seconds_since(t0);
      ++report.jacobians;
      t0 = Clock::now();
      if (!solver.factorize(A.matrix())) {
        report.message = "system matrix is not positive definite";
        return report;
      }
      report.timings.factorization += seconds_since(t0);
      t0 = Clock::now();
    }
    const bool first = report.iterations == 1 && problem.first_increment;
    if (first && problem.first_increment->size() == du.size())
      du = *problem.first_increment;
    else
      du.setZero();
    // Inexact Newton for iterative solvers (Eisenstat–Walker style forcing term): the first
    // solve to 1e-3 (the step's nonlinearity leaves about that anyway), later ones to a tenth
    // of what the target still needs.
    const double linear_tol = std::clamp(
        std::max(0.3 * target / norm, 1e-3 * norm / report.initial_residual), 1e-12, 1e-2);
    const bool solved = solver.solve(-g, du, linear_tol);
    report.timings.solve += seconds_since(t0);
    report.linear_iterations += solver.last_iterations();
    if (!solved) {
      report.message = "linear solve failed";
      return report;
    }
    if (first)
      *problem.first_increment = du;
    u_prev = u;
    const double norm_prev = norm;
    if (problem.energy) {
      // Armijo backtracking on the energy whose gradient is g (statics, hyperelastic).
      const double e0 = problem.energy(u_prev);
      const double slope = g.dot(du);
      double alpha = 1;
      t0 = Clock::now();
      for (int ls = 0; ls < options.max_line_search; ++ls, alpha *= 0.5) {
        u = u_prev + alpha * du;
        const double e = problem.energy(u);
        if (std::isfinite(e) && e <= e0 + 1e-4 * alpha * std::min(slope, 0.0))
          break;
      }
      report.timings.assembly += seconds_since(t0);
      norm = evaluate(u);
      reuse_jacobian = reuse_after(alpha, norm_prev, norm);
      continue;
    }
    // No energy (dynamics with damping or a learned correction): take the full Newton step, which
    // the mass term keeps well-behaved, and back off only when the state turns non-finite or the
    // residual explodes. A test on ‖g‖ alone would refuse the first step of stiff bending
    // problems, whose residual transiently grows before Newton turns quadratic. The residual at
    // the new point is also the next iteration's convergence test.
    u = u_prev + du;
    norm = evaluate(u);
    double alpha = 0.5;
    for (int ls = 0;
         ls < options.max_line_search && !(std::isfinite(norm) && norm <= 1e3 * norm_prev);
         ++ls, alpha *= 0.5) {
      u = u_prev + alpha * du;
      norm = evaluate(u);
    }
    reuse_jacobian = reuse_after(2 * alpha, norm_prev, norm); // the step taken is 2α
  }
}

} // namespace elastolearn::sim
