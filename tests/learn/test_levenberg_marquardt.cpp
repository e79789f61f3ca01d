// The Levenberg–Marquardt driver (learn/levenberg_marquardt.hpp) on small problems with known
// answers: it solves them, rejects a step that raises the cost or whose evaluation fails (and
// grows the damping by the factor for each), holds an unknown that moves nothing, and stops for
// each of its reasons.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/levenberg_marquardt.hpp>
#include <elastolearn/learn/stability_cuts.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

namespace elastolearn::learn {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// min ‖r(x)‖² from x0 with the Jacobian J(x) given: a LevenbergMarquardtProblem whose point is
/// `x`, with a log of every trial step. `fails(x)` makes a trial's evaluation fail (a stand-in for
/// a diverging simulation).
struct LeastSquares {
  std::function<VecX(const VecX&)> residual;
  std::function<MatX(const VecX&)> jacobian;
  VecX x;
  std::function<bool(const VecX&)> fails = [](const VecX&) { return false; };
  VecX lower {}; ///< lower bounds on x (empty: none), given to the driver as lower_step
  VecX trial {};
  std::vector<VecX> tried {}; ///< every trial point
  std::vector<LevenbergMarquardtStep> steps {};
  int accepts = 0; ///< calls of accept

  double cost(const VecX& at) const { return residual(at).squaredNorm(); }

  LevenbergMarquardtProblem problem() {
    LevenbergMarquardtProblem p;
    p.linearize = [this]() -> std::optional<NormalEquations> {
      const MatX j = jacobian(x);
      VecX lower_step;
      if (lower.size() > 0)
        lower_step = (lower - x).cwiseMin(0.0);
      return NormalEquations { j.transpose() * j, j.transpose() * residual(x), cost(x), 1,
        lower_step };
    };
    p.evaluate = [this](const VecX& step) {
      trial = x + step;
      tried.push_back(trial);
      if (fails(trial))
        return TrialEvaluation {};
      return TrialEvaluation { .completed = true, .cost = cost(trial) };
    };
    p.accept = [this] {
      x = trial;
      ++accepts;
    };
    p.on_step = [this](const LevenbergMarquardtStep& s) {
      steps.push_back(s);
      return true;
    };
    return p;
  }
  LevenbergMarquardtSummary solve(const LevenbergMarquardtOptions& options) {
    return levenberg_marquardt(problem(), options);
  }
};

/// Rosenbrock's function as residuals, r = (10 (x₂ − x₁²), 1 − x₁): minimum 0 at (1, 1).
VecX rosenbrock_residual(const VecX& x) {
  return Eigen::Vector2d(10 * (x[1] - x[0] * x[0]), 1 - x[0]);
}
MatX rosenbrock_jacobian(const VecX& x) {
  MatX j(2, 2);
  j << -20 * x[0], 10, -1, 0;
  return j;
}
LeastSquares rosenbrock() {
  return { rosenbrock_residual, rosenbrock_jacobian, Eigen::Vector2d(-1.2, 1.0) };
}

/// r(x) = atan(x): minimum 0 at 0. From x = 2 the Gauss–Newton step −atan(x)(1 + x²) lands at
/// x ≈ −3.5, where |atan| is larger: the undamped step raises the cost.
VecX arctangent_residual(const VecX& x) {
  return VecX::Constant(1, std::atan(x[0]));
}
MatX arctangent_jacobian(const VecX& x) {
  return MatX::Constant(1, 1, 1 / (1 + x[0] * x[0]));
}
LeastSquares arctangent() {
  return { arctangent_residual, arctangent_jacobian, VecX::Constant(1, 2.0) };
}

class BothScalings : public ::testing::TestWithParam<DampingScaling> { };

TEST_P(BothScalings, SolvesRosenbrock) {
  LeastSquares ls = rosenbrock();
  const auto s = ls.solve({ .scaling = GetParam(), .function_tolerance = 1e-12 });
  EXPECT_NEAR(ls.x[0], 1.0, 1e-8);
  EXPECT_NEAR(ls.x[1], 1.0, 1e-8);
  EXPECT_NE(s.stop, LevenbergMarquardtStop::max_iterations);
  EXPECT_EQ(s.steps, static_cast<int>(ls.steps.size()));
  EXPECT_EQ(
      s.iterations, s.accepted + (s.stop == LevenbergMarquardtStop::no_improving_step ? 1 : 0));
  // Every accepted step lowered the cost.
  for (const auto& step : ls.steps) {
    if (step.accepted) {
      EXPECT_GT(step.relative_decrease, 0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(LevenbergMarquardt, BothScalings,
    ::testing::Values(DampingScaling::marquardt, DampingScaling::jacobi), [](const auto& info) {
      return info.param == DampingScaling::marquardt ? "marquardt" : "jacobi";
    });

TEST(LevenbergMarquardt, AStepSolverHoldsEveryTrialToItsConditions) {
  // Rosenbrock subject to x₁ ≤ 0.5 through solve_step (the forward fit's stability cuts): the
  // constrained minimum of (1 − x₁)² + 100 (x₂ − x₁²)² is at (0.5, 0.25), on the boundary, and
  // no trial point leaves the feasible side.
  LeastSquares ls = rosenbrock();
  LevenbergMarquardtProblem problem = ls.problem();
  problem.solve_step = [&](const RegularisedNormalEquations& equations, const VecX& rhs,
                           const LinearInequalities&) {
    LinearInequalities bound; // −(x₁ + δ₁) ≥ −0.5
    bound.rows = Eigen::RowVector2d(-1, 0);
    bound.bounds = VecX::Constant(1, -0.5 + ls.x[0]);
    return solve_with_inequalities(equations, rhs, bound);
  };
  levenberg_marquardt(problem, { .function_tolerance = 1e-14 });
  EXPECT_NEAR(ls.x[0], 0.5, 1e-7);
  EXPECT_NEAR(ls.x[1], 0.25, 1e-6);
  for (const VecX& trial : ls.tried)
    EXPECT_LE(trial[0], 0.5 + 1e-9);
}

TEST(LevenbergMarquardt, RejectsAWorseOrFailedStepAndRetriesShorterFromTheSamePoint) {
  // μ = 10⁻³: the first step is nearly the Gauss–Newton step to x ≈ −3.5, which raises the cost;
  // with `failing`, trials below x = −1 "diverge" instead. Either is rejected, μ grows by the
  // factor for that kind of rejection (different here, so the damping tells them apart), and a
  // shorter step from x = 2 follows; the solve still reaches the minimum.
  for (const bool failing : { false, true }) {
    SCOPED_TRACE(failing ? "failed evaluation" : "higher cost");
    LeastSquares ls = arctangent();
    if (failing)
      ls.fails = [](const VecX& x) { return x[0] < -1; };
    const auto s = ls.solve({ .initial_damping = 1e-3,
        .scaling = DampingScaling::jacobi,
        .damping_increase = 4,
        .failed_damping_increase = 10 });
    ASSERT_GE(ls.steps.size(), 2u);
    const LevenbergMarquardtStep& first = ls.steps.front();
    EXPECT_EQ(first.completed, !failing);
    EXPECT_FALSE(first.accepted);
    EXPECT_EQ(first.rejections, 1);
    if (failing) {
      EXPECT_EQ(first.cost, std::numeric_limits<double>::infinity());
      EXPECT_DOUBLE_EQ(first.damping, 1e-2); // × failed_damping_increase
    } else {
      EXPECT_GT(first.cost, std::atan(2.0) * std::atan(2.0));
      EXPECT_DOUBLE_EQ(first.damping, 4e-3); // × damping_increase
    }
    // The next trial comes from the same equations and point (the rejected one was not kept):
    // the same direction, shorter.
    EXPECT_EQ(ls.steps[1].iteration, 1);
    EXPECT_LT(ls.tried[1][0], 2.0);
    EXPECT_GT(ls.tried[1][0], ls.tried[0][0]);
    EXPECT_NEAR(ls.x[0], 0.0, 1e-8);
    EXPECT_GT(s.accepted, 0);
    EXPECT_EQ(ls.accepts, s.accepted);
  }
}

TEST(LevenbergMarquardt, GivesUpAfterMaxRejectionsInARow) {
  LeastSquares ls = arctangent();
  ls.fails = [](const VecX&) { return true; };
  const auto s = ls.solve({ .max_rejections = 3, .initial_damping = 1e-3 });
  EXPECT_EQ(s.stop, LevenbergMarquardtStop::no_improving_step);
  EXPECT_EQ(s.steps, 3);
  EXPECT_EQ(s.rejections, 3);
  EXPECT_EQ(s.accepted, 0);
  ASSERT_EQ(ls.steps.size(), 3u);
  EXPECT_FALSE(ls.steps[1].gives_up);
  EXPECT_TRUE(ls.steps[2].gives_up);
  EXPECT_EQ(ls.x[0], 2.0); // never moved
  EXPECT_DOUBLE_EQ(s.damping, 1.0); // 10⁻³ × failed_damping_increase³
}

TEST(LevenbergMarquardt, MarquardtScalingHoldsAnUnknownThatMovesNothing) {
  // r = (x₀ − 3, 0·x₁): x₁ does not move the residuals (zero column) and must not move.
  LeastSquares ls { .residual = [](const VecX& x) { return VecX::Constant(1, x[0] - 3); },
    .jacobian = [](const VecX&) { return MatX(Eigen::RowVector2d(1, 0)); },
    .x = Eigen::Vector2d(0, 5) };
  const LevenbergMarquardtOptions marquardt { .scaling = DampingScaling::marquardt };
  ls.solve(marquardt);
  EXPECT_NEAR(ls.x[0], 3.0, 1e-9);
  EXPECT_EQ(ls.x[1], 5.0);

  // With no unknown that moves anything there is no step at all.
  ls.jacobian = [](const VecX&) { return MatX(MatX::Zero(1, 2)); };
  const auto s = ls.solve(marquardt);
  EXPECT_EQ(s.stop, LevenbergMarquardtStop::degenerate);
  EXPECT_EQ(s.steps, 0);
}

TEST(LevenbergMarquardt, AnUnknownOnItsBoundIsHeldThereAndTheOthersStepInFull) {
  // r = A x − b, linear, with x₂ ≥ 0 required and the unconstrained minimum at (3, −2, −20). The
  // bounded minimum is (3, −2, 0): A's last column is orthogonal to the others, and its gradient
  // there pushes x₂ down (the bound is active: KKT). Held at the bound, x₂ does not shorten the
  // others' steps through max_step: the first trial is the bounded Gauss–Newton step (damped by
  // μ = 10⁻³), and the solve ends at the bounded minimum in a few steps. Unbounded, the first
  // step is scaled to x₂'s max_step of 4, and so x₀'s to 0.6.
  MatX a(4, 3);
  a << 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5, 0.5, 0;
  const VecX b = a * Eigen::Vector3d(3, -2, -20);
  LeastSquares ls { .residual = [&](const VecX& x) { return VecX(a * x - b); },
    .jacobian = [&](const VecX&) { return a; },
    .x = Eigen::Vector3d::Zero(),
    .lower = Eigen::Vector3d(-kInf, -kInf, 0) };
  const LevenbergMarquardtOptions options { .max_iterations = 50,
    .scaling = DampingScaling::marquardt,
    .max_step = 4,
    .function_tolerance = 1e-12 };
  ls.solve(options);
  const VecX bounded = Eigen::Vector3d(3, -2, 0);
  ASSERT_GT((a.transpose() * (a * bounded - b))[2], 0); // the bound is active
  EXPECT_LT((ls.tried.front() - bounded).norm(), 1e-2) << ls.tried.front().transpose();
  EXPECT_LT((ls.x - bounded).norm(), 1e-9) << ls.x.transpose();
  EXPECT_LE(ls.steps.size(), 6u);
  for (const VecX& t : ls.tried)
    EXPECT_EQ(t[2], 0.0);

  LeastSquares unbounded = ls;
  unbounded.x = Eigen::Vector3d::Zero();
  unbounded.lower = VecX();
  unbounded.tried.clear();
  unbounded.solve(options);
  EXPECT_NEAR(unbounded.tried.front()[0], 0.6, 1e-2);
  EXPECT_LT((unbounded.x - Eigen::Vector3d(3, -2, -20)).norm(), 1e-9);
}

TEST(LevenbergMarquardt, ClipsLongStepsToMaxStep) {
  LeastSquares ls = arctangent();
  ls.solve({ .scaling = DampingScaling::marquardt, .max_step = 0.25 });
  EXPECT_NEAR(ls.tried.front()[0], 2.0 - 0.25, 1e-12);
  EXPECT_NEAR(ls.x[0], 0.0, 1e-8);
}

TEST(LevenbergMarquardt, StopsAtTheBudgetsAndWhenTheProblemSaysSo) {
  LeastSquares steps = rosenbrock();
  const auto by_steps = steps.solve({ .max_steps = 2 });
  EXPECT_EQ(by_steps.stop, LevenbergMarquardtStop::max_steps);
  EXPECT_EQ(by_steps.steps, 2);
  EXPECT_EQ(steps.solve({ .max_steps = 0 }).iterations, 0);

  LeastSquares iterations = rosenbrock();
  const auto by_iterations = iterations.solve({ .max_iterations = 1 });
  EXPECT_EQ(by_iterations.stop, LevenbergMarquardtStop::max_iterations);
  EXPECT_EQ(by_iterations.iterations, 1);
  EXPECT_EQ(by_iterations.accepted, 1);

  // A large tolerance: the first accepted step already counts as converged.
  LeastSquares tolerance = arctangent();
  const auto by_tolerance = tolerance.solve({ .function_tolerance = 1.0 });
  EXPECT_EQ(by_tolerance.stop, LevenbergMarquardtStop::converged);
  EXPECT_EQ(by_tolerance.accepted, 1);

  LeastSquares ls = rosenbrock();
  LevenbergMarquardtProblem p = ls.problem();
  p.on_step = [](const LevenbergMarquardtStep&) { return false; };
  EXPECT_EQ(levenberg_marquardt(p, {}).steps, 1);
  p.linearize = [] { return std::optional<NormalEquations>(); };
  const auto s = levenberg_marquardt(p, {});
  EXPECT_EQ(s.stop, LevenbergMarquardtStop::stopped);
  EXPECT_EQ(s.iterations, 0);
}

TEST(LevenbergMarquardt, TheToleranceMeasuresADecreaseAgainstTheCostAboveItsFloor) {
  // r = (atan x, 100): a residual of 100 no x fits (noise), and from x = 2 the learnable part
  // atan²(2) ≈ 1.23 of a cost of 10⁴. Against the whole cost the first accepted step looks
  // negligible (< 1 %) and ends the solve far from the minimum; against the cost above the
  // floor of 10⁴ the solve goes on to it.
  const auto noisy = [] {
    return LeastSquares { [](const VecX& x) { return Eigen::Vector2d(std::atan(x[0]), 100.0); },
      [](const VecX& x) {
        MatX j = MatX::Zero(2, 1);
        j(0, 0) = 1 / (1 + x[0] * x[0]);
        return j;
      },
      VecX::Constant(1, 2.0) };
  };
  LeastSquares whole = noisy();
  const auto stopped = whole.solve({ .function_tolerance = 0.01 });
  EXPECT_EQ(stopped.stop, LevenbergMarquardtStop::converged);
  EXPECT_EQ(stopped.accepted, 1);
  EXPECT_GT(std::abs(whole.x[0]), 0.05);

  LeastSquares above = noisy();
  // (It ends where the cost's round-off, ~10⁻¹² of 10⁴, hides further decreases.)
  const auto solved = above.solve({ .function_tolerance = 0.01, .cost_floor = 1e4 });
  EXPECT_GT(solved.accepted, 1);
  EXPECT_LT(std::abs(above.x[0]), 1e-3);

  // A floor above the cost: the tolerance never ends the solve.
  LeastSquares below = noisy();
  const auto s = below.solve({ .max_steps = 20, .function_tolerance = 0.01, .cost_floor = 2e4 });
  EXPECT_NE(s.stop, LevenbergMarquardtStop::converged);
  EXPECT_EQ(below.steps.front().relative_decrease, 0); // rejected: the undamped overshoot
  for (const auto& step : below.steps)
    if (step.accepted) {
      EXPECT_EQ(step.relative_decrease, kInf);
    }
}

TEST(LevenbergMarquardt, RejectsBadOptions) {
  const auto bad = [](auto change) {
    LevenbergMarquardtOptions o;
    change(o);
    EXPECT_THROW(o.validate(), InputError);
  };
  EXPECT_NO_THROW(LevenbergMarquardtOptions {}.validate());
  bad([](auto& o) { o.max_iterations = 0; });
  bad([](auto& o) { o.max_steps = -1; });
  bad([](auto& o) { o.max_rejections = 0; });
  bad([](auto& o) { o.initial_damping = 0; });
  bad([](auto& o) { o.damping_decrease = 0.5; });
  bad([](auto& o) { o.min_damping = -1; });
  bad([](auto& o) { o.damping_increase = 1; });
  bad([](auto& o) { o.failed_damping_increase = std::nan(""); });
  bad([](auto& o) { o.max_step = 0; });
  bad([](auto& o) { o.function_tolerance = -1; });
  bad([](auto& o) { o.cost_floor = -1; });
  bad([](auto& o) { o.cost_floor = kInf; });
}

} // namespace
} // namespace elastolearn::learn
