#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/levenberg_marquardt.hpp>
#include <elastolearn/learn/rbf_fit.hpp>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors levenberg_marquardt_error("levenberg_marquardt");

/// Below this fraction of the largest diagonal entry an unknown counts as not moving the
/// residuals (marquardt scaling holds it fixed).
constexpr double kInactiveDiagonal = 1e-14;

/// The normal equations of one iteration and the damped steps from them.
class DampedSystem {
  public:
  DampedSystem(
      NormalEquations equations, DampingScaling scaling, const LevenbergMarquardtProblem& problem)
      : m_equations(std::move(equations))
      , m_scaling(scaling)
      , m_problem(problem) {
    const MatX& h = m_equations.hessian;
    ELASTOLEARN_CHECK(
        h.rows() > 0 && h.rows() == h.cols() && m_equations.gradient.size() == h.rows(),
        "the normal equations must be n × n and n with n ≥ 1");
    const VecX& lower = m_equations.lower_step;
    ELASTOLEARN_CHECK(lower.size() == 0
            || (lower.size() == h.rows()
                && (lower.array() < std::numeric_limits<double>::infinity()).all()),
        "lower step bounds must be one per unknown, each below +∞ (−∞: none)");
    const Eigen::Index bounded = lower.array().isFinite().count();
    m_bounds.rows = MatX::Zero(bounded, h.rows());
    m_bounds.bounds.resize(bounded);
    for (Eigen::Index i = 0, k = 0; i < lower.size(); ++i)
      if (std::isfinite(lower[i])) {
        m_bounds.rows(k, i) = 1;
        m_bounds.bounds[k++] = lower[i];
      }
    if (m_scaling == DampingScaling::marquardt) {
      const double diag_max = h.diagonal().maxCoeff();
      m_degenerate = !(diag_max > 0);
      m_active.resize(static_cast<size_t>(h.rows()));
      for (Eigen::Index i = 0; i < h.rows(); ++i)
        m_active[static_cast<size_t>(i)] = h(i, i) > kInactiveDiagonal * diag_max;
    }
  }

  /// No step can be formed (marquardt: no unknown moves the residuals).
  bool degenerate() const { return m_degenerate; }
  double cost() const { return m_equations.cost; }

  /// The step for damping `mu`, scaled down to `max_step` in its largest entry.
  VecX step(double mu, double max_step) const {
    VecX delta = m_scaling == DampingScaling::marquardt ? marquardt_step(mu) : jacobi_step(mu);
    const double largest = delta.cwiseAbs().maxCoeff();
    if (largest > max_step)
      delta *= max_step / largest;
    return delta;
  }

  private:
  /// (H + μ diag H) δ = −g over the unknowns that move, each held one at its lower bound where
  /// the solve would cross it (at most n solves: each adds a held unknown).
  VecX marquardt_step(double mu) const {
    const Eigen::Index n = m_equations.hessian.rows();
    const VecX& lower = m_equations.lower_step;
    // held[i]: δ_i is fixed, at 0 (an unknown that does not move the residuals) or at its bound.
    std::vector<bool> held(static_cast<size_t>(n));
    VecX fixed = VecX::Zero(n);
    for (Eigen::Index i = 0; i < n; ++i)
      held[static_cast<size_t>(i)] = !m_active[static_cast<size_t>(i)];
    while (true) {
      MatX a = m_equations.hessian;
      VecX rhs = -m_equations.gradient - m_equations.hessian * fixed;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (held[static_cast<size_t>(i)]) {
          a.row(i).setZero();
          a.col(i).setZero();
          a(i, i) = 1;
          rhs[i] = fixed[i];
        } else {
          a(i, i) *= 1 + mu;
        }
      }
      const VecX delta = a.ldlt().solve(rhs);
      bool crossed = false;
      for (Eigen::Index i = 0; i < lower.size(); ++i)
        if (!held[static_cast<size_t>(i)] && delta[i] < lower[i]) {
          held[static_cast<size_t>(i)] = true;
          fixed[i] = lower[i];
          crossed = true;
        }
      if (!crossed)
        return delta;
    }
  }

  VecX jacobi_step(double mu) const {
    const Eigen::Index n = m_equations.hessian.rows();
    const RegularisedNormalEquations damped(
        m_equations.hessian, VecX::Constant(n, mu), m_equations.samples);
    const VecX rhs = -m_equations.gradient;
    return m_problem.solve_step ? m_problem.solve_step(damped, rhs, m_bounds)
                                : solve_with_inequalities(damped, rhs, m_bounds);
  }

  NormalEquations m_equations;
  DampingScaling m_scaling;
  const LevenbergMarquardtProblem& m_problem;
  std::vector<bool> m_active; ///< marquardt: unknowns that move the residuals
  LinearInequalities m_bounds; ///< jacobi: the finite lower_step entries as δ_i ≥ lower_i
  bool m_degenerate = false;
};

} // namespace

void LevenbergMarquardtOptions::validate() const {
  if (max_iterations < 1)
    levenberg_marquardt_error("max_iterations", "must be ≥ 1, got " + to_text(max_iterations));
  if (max_steps < 0)
    levenberg_marquardt_error("max_steps", "must be ≥ 0, got " + to_text(max_steps));
  if (max_rejections < 1)
    levenberg_marquardt_error("max_rejections", "must be ≥ 1, got " + to_text(max_rejections));
  if (!(initial_damping > 0 && std::isfinite(initial_damping)))
    levenberg_marquardt_error(
        "initial_damping", "must be finite and > 0, got " + to_text(initial_damping));
  if (!(damping_decrease >= 1 && std::isfinite(damping_decrease)))
    levenberg_marquardt_error(
        "damping_decrease", "must be finite and ≥ 1, got " + to_text(damping_decrease));
  if (!(min_damping >= 0 && std::isfinite(min_damping)))
    levenberg_marquardt_error("min_damping", "must be finite and ≥ 0, got " + to_text(min_damping));
  if (!(damping_increase > 1 && std::isfinite(damping_increase)))
    levenberg_marquardt_error(
        "damping_increase", "must be finite and > 1, got " + to_text(damping_increase));
  if (!(failed_damping_increase > 1 && std::isfinite(failed_damping_increase)))
    levenberg_marquardt_error("failed_damping_increase",
        "must be finite and > 1, got " + to_text(failed_damping_increase));
  if (!(max_step > 0))
    levenberg_marquardt_error("max_step", "must be > 0, got " + to_text(max_step));
  if (!(function_tolerance >= 0 && std::isfinite(function_tolerance)))
    levenberg_marquardt_error(
        "function_tolerance", "must be finite and ≥ 0, got " + to_text(function_tolerance));
  if (!(cost_floor >= 0 && std::isfinite(cost_floor)))
    levenberg_marquardt_error("cost_floor", "must be finite and ≥ 0, got " + to_text(cost_floor));
}

LevenbergMarquardtSummary levenberg_marquardt(
    const LevenbergMarquardtProblem& problem, const LevenbergMarquardtOptions& options) {
  options.validate();
  ELASTOLEARN_CHECK(problem.linearize && problem.evaluate && problem.accept,
      "a Levenberg–Marquardt problem needs linearize, evaluate and accept");
  LevenbergMarquardtSummary summary;
  summary.damping = options.initial_damping;
  const auto end = [&](LevenbergMarquardtStop stop) {
    summary.stop = stop;
    return summary;
  };
  double& mu = summary.damping;
  while (true) {
    if (summary.iterations >= options.max_iterations)
      return end(LevenbergMarquardtStop::max_iterations);
    if (summary.steps >= options.max_steps)
      return end(LevenbergMarquardtStop::max_steps);
    std::optional<NormalEquations> equations = problem.linearize();
    if (!equations)
      return end(LevenbergMarquardtStop::stopped);
    ++summary.iterations;
    const DampedSystem system(std::move(*equations), options.scaling, problem);
    if (system.degenerate())
      return end(LevenbergMarquardtStop::degenerate);
    summary.rejections = 0;
    while (true) {
      if (summary.steps >= options.max_steps)
        return end(LevenbergMarquardtStop::max_steps);
      const TrialEvaluation trial = problem.evaluate(system.step(mu, options.max_step));
      ++summary.steps;
      if (trial.stop)
        return end(LevenbergMarquardtStop::stopped);
      LevenbergMarquardtStep step;
      step.iteration = summary.iterations;
      step.completed = trial.completed;
      step.accepted = trial.completed && trial.cost < system.cost();
      step.cost = trial.completed ? trial.cost : std::numeric_limits<double>::infinity();
      if (step.accepted) {
        const double excess = system.cost() - options.cost_floor;
        step.relative_decrease = excess > 0 ? (system.cost() - trial.cost) / excess
                                            : std::numeric_limits<double>::infinity();
        summary.relative_decrease = step.relative_decrease;
        ++summary.accepted;
        mu = std::max(mu / options.damping_decrease, options.min_damping);
        problem.accept();
      } else {
        mu *= trial.completed ? options.damping_increase : options.failed_damping_increase;
        ++summary.rejections;
        step.gives_up = summary.rejections >= options.max_rejections;
      }
      step.rejections = summary.rejections;
      step.damping = mu;
      if (problem.on_step && !problem.on_step(step))
        return end(LevenbergMarquardtStop::stopped);
      if (step.gives_up)
        return end(LevenbergMarquardtStop::no_improving_step);
      if (step.accepted) {
        if (step.relative_decrease < options.function_tolerance)
          return end(LevenbergMarquardtStop::converged);
        break;
      }
    }
  }
}

} // namespace elastolearn::learn
