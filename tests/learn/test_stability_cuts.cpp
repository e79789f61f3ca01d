// Stability cuts (issue 19, "stable corrections"): the inequality-constrained least squares
// satisfies the KKT conditions of a brute-force active-set enumeration; a cut is the exact
// directional stiffness of the corrected material (a Lamé change scaled until it keeps the cut's
// fraction of the nominal); a fit whose data demand an unstable material is held stable, and
// only where it must be.
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/stability_cuts.hpp>
#include <elastolearn/material/corotated.hpp>

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace elastolearn::learn {
namespace {

const material::Lame k_lame = material::Lame::from_young_poisson(1e5, 0.4);
const material::CorotatedModel k_nominal(k_lame);

/// Energy kernels, the linear and cubic tails, no damping: the recipe's elastic design.
RbfFitOptions elastic_options() {
  RbfFitOptions o;
  o.energy_kernels = true;
  o.epsilon = 0.03;
  o.fit_damping = false;
  return o;
}

/// Sorted stretches on a grid over [0.8, 1.25].
MatX stretch_grid(double step) {
  MatX s(0, 3);
  for (double a = 0.8; a <= 1.25 + 1e-9; a += step)
    for (double b = 0.8; b <= a + 1e-9; b += step)
      for (double c = 0.8; c <= b + 1e-9; c += step) {
        s.conservativeResize(s.rows() + 1, 3);
        s.row(s.rows() - 1) << a, b, c;
      }
  return s;
}

/// The normal equations of fitting design's N(σ) to `target(σ)` at every row of `samples`.
template <class Target>
std::pair<MatX, VecX> stress_normal_equations(
    const RbfDesign& design, const MatX& samples, const Target& target) {
  const int u = design.num_unknowns();
  MatX normal = MatX::Zero(u, u);
  VecX rhs = VecX::Zero(u);
  RbfDesign::OutputMatrix a(3, design.elastic_unknowns());
  for (Eigen::Index i = 0; i < samples.rows(); ++i) {
    const Vec3 s = samples.row(i).transpose();
    design.output_matrix(s, a);
    normal.topLeftCorner(a.cols(), a.cols()) += a.transpose() * a;
    rhs.head(a.cols()) += a.transpose() * target(s);
  }
  return { normal, rhs };
}

TEST(StabilityCuts, TheConstrainedSolveMeetsTheKktConditionsOfEveryActiveSet) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 20; ++trial) {
    const int u = 5, k = 3;
    MatX b(8, u);
    for (Eigen::Index i = 0; i < b.size(); ++i)
      b.data()[i] = n01(rng);
    const MatX q = b.transpose() * b + MatX::Identity(u, u);
    VecX rhs(u);
    for (int i = 0; i < u; ++i)
      rhs[i] = n01(rng);
    LinearInequalities g;
    g.rows.resize(k, u);
    g.bounds.resize(k);
    for (Eigen::Index i = 0; i < g.rows.size(); ++i)
      g.rows.data()[i] = n01(rng);
    for (int i = 0; i < k; ++i)
      g.bounds[i] = n01(rng);
    const RegularisedNormalEquations equations(q, VecX::Zero(u), 8);
    const VecX x = solve_with_inequalities(equations, rhs, g);
    // The reference: the unique active set whose KKT point is feasible with λ ≥ 0.
    VecX reference;
    for (int set = 0; set < (1 << k); ++set) {
      std::vector<int> active;
      for (int i = 0; i < k; ++i)
        if (set & (1 << i))
          active.push_back(i);
      const int a = static_cast<int>(active.size());
      MatX kkt = MatX::Zero(u + a, u + a);
      VecX right(u + a);
      kkt.topLeftCorner(u, u) = q;
      right.head(u) = rhs;
      for (int r = 0; r < a; ++r) {
        kkt.block(0, u + r, u, 1) = -g.rows.row(active[r]).transpose();
        kkt.block(u + r, 0, 1, u) = g.rows.row(active[r]);
        right[u + r] = g.bounds[active[r]];
      }
      const VecX z = kkt.fullPivLu().solve(right);
      const VecX candidate = z.head(u);
      if ((z.tail(a).array() >= -1e-12).all()
          && ((g.rows * candidate - g.bounds).array() >= -1e-10).all()) {
        reference = candidate;
        break;
      }
    }
    ASSERT_EQ(reference.size(), u) << "trial " << trial;
    EXPECT_LT((x - reference).norm(), 1e-7 * (1 + reference.norm())) << "trial " << trial;
    EXPECT_GE((g.rows * x - g.bounds).minCoeff(), -1e-8) << "trial " << trial;
  }
}

TEST(StabilityCuts, ACutIsTheDirectionalStiffnessOfTheCorrectedMaterial) {
  // A Lamé change of −1.5 × the nominal's: nominal + s × it has (1 − 1.5 s) × the nominal's
  // stiffness in every direction (stretch block and twists), so each cut's boundary on the ray
  // s x is where that is kCutKeptStiffness: s = (1 − kept)/1.5 = 0.6.
  const RbfDesign design(Vec3(2.0, 2.0, 2.0).transpose(), elastic_options());
  material::RbfCorrection::Parameters p;
  p.energy_kernels = true;
  p.epsilon = 0.03;
  p.centres = Vec3(2.0, 2.0, 2.0).transpose();
  p.weights = VecX::Zero(1);
  p.own_slope = -1.5 * (2 * k_lame.mu + k_lame.lambda);
  p.other_slope = -1.5 * k_lame.lambda;
  const VecX x = design.unknowns(material::RbfCorrection(p));
  MatX sample(1, 3);
  sample << 1.2, 0.95, 0.9;
  const LinearInequalities cuts = stability_cuts(design, k_nominal, x, sample);
  ASSERT_EQ(cuts.size(), 4); // the stretch block and all three twists are negative
  for (Eigen::Index i = 0; i < cuts.size(); ++i) {
    EXPECT_NEAR(cuts.rows.row(i).norm(), 1, 1e-12);
    EXPECT_LT(cuts.rows.row(i).dot(x), cuts.bounds[i]); // violated by the correction …
    EXPECT_LT(cuts.bounds[i], 0); // … not by the nominal
    EXPECT_NEAR(cuts.bounds[i] / cuts.rows.row(i).dot(x), (1 - kCutKeptStiffness) / 1.5, 1e-9);
  }
  // Stable samples give no cut.
  EXPECT_EQ(stability_cuts(design, k_nominal, 0.5 * x, sample).size(), 0);
}

TEST(StabilityCuts, AFitWhoseDataDemandAnUnstableMaterialIsHeldStable) {
  // Data from a material softer than stable (the nominal's stress times −0.5 in all): the
  // unconstrained fit reproduces it and is unstable everywhere; held by the cuts, the fit is
  // stable at every sample and keeps about the cut's fraction of the nominal's stiffness.
  const MatX samples = stretch_grid(0.05);
  const MatX centres = samples.topRows(20);
  const RbfDesign design(centres, elastic_options());
  const auto [normal, rhs] = stress_normal_equations(
      design, samples, [](const Vec3& s) { return Vec3(-1.5 * k_nominal.principal_stress(s)); });
  const RegularisedNormalEquations equations(normal, design.regularization_weights(), 1);
  const VecX free = equations.solve(rhs);
  const material::RbfCorrection unconstrained = design.correction(free);
  EXPECT_LT(material_stability(k_nominal, &unconstrained, samples).min_relative_eigenvalue, -0.4);

  const StableSolve held = stable_least_squares(
      equations, rhs, design, k_nominal, samples, VecX::Zero(design.num_unknowns()));
  const material::RbfCorrection stable = design.correction(held.x);
  const StabilityReport report = material_stability(k_nominal, &stable, samples);
  EXPECT_TRUE(report.stable()) << report.unstable_samples << " unstable, worst "
                               << report.min_relative_eigenvalue;
  EXPECT_GT(held.cuts, 0);
  EXPECT_LT(report.min_relative_eigenvalue, 2 * kCutKeptStiffness); // held at the edge, no softer
}

TEST(StabilityCuts, AFitThatIsStableIsLeftAsItIs) {
  const MatX samples = stretch_grid(0.05);
  const RbfDesign design(samples.topRows(20), elastic_options());
  const auto [normal, rhs] = stress_normal_equations(
      design, samples, [](const Vec3& s) { return Vec3(0.5 * k_nominal.principal_stress(s)); });
  const RegularisedNormalEquations equations(normal, design.regularization_weights(), 1);
  const StableSolve held = stable_least_squares(
      equations, rhs, design, k_nominal, samples, VecX::Zero(design.num_unknowns()));
  EXPECT_EQ(held.cuts, 0);
  EXPECT_EQ(held.rounds, 0);
  EXPECT_EQ(held.x, equations.solve(rhs));
}

TEST(StabilityCuts, ALocalSofteningIsCutAndTheRestOfTheFitKept) {
  // Data of a kernel softening around (1.2, 1.2, 1.2) that removes more than the nominal's
  // stiffness there, plus a stiffening of 20 % everywhere. Held stable by the cuts, the fit
  // follows the data far better than the largest stable fraction ½ᵏ of the unconstrained fit
  // (the loop's fallback), which gives up the fit everywhere (measured: 0.20 against 0.88 of
  // the data's RMS).
  material::RbfCorrection::Parameters truth;
  truth.energy_kernels = true;
  truth.epsilon = 0.03;
  truth.centres = Vec3(1.2, 1.2, 1.2).transpose();
  truth.weights = VecX::Constant(1, -2e3);
  truth.own_slope = 0.2 * (2 * k_lame.mu + k_lame.lambda);
  truth.other_slope = 0.2 * k_lame.lambda;
  const material::RbfCorrection target(truth);
  const MatX samples = stretch_grid(0.025);
  MatX centres(21, 3);
  centres.topRows(20) = stretch_grid(0.1).topRows(20);
  centres.row(20) = truth.centres.row(0);
  const RbfDesign design(centres, elastic_options());
  const auto [normal, rhs] = stress_normal_equations(
      design, samples, [&](const Vec3& s) { return target.correction(s, Vec3::Zero()); });
  const RegularisedNormalEquations equations(normal, design.regularization_weights(), 1);
  const material::RbfCorrection unconstrained = design.correction(equations.solve(rhs));
  ASSERT_FALSE(material_stability(k_nominal, &unconstrained, samples).stable());
  const StableSolve held = stable_least_squares(
      equations, rhs, design, k_nominal, samples, VecX::Zero(design.num_unknowns()));
  const material::RbfCorrection stable = design.correction(held.x);
  EXPECT_TRUE(material_stability(k_nominal, &stable, samples).stable());
  // The largest stable fraction ½ᵏ of the unconstrained fit.
  double kept = 1;
  material::RbfCorrection shrunk = unconstrained;
  while (!material_stability(k_nominal, &shrunk, samples).stable() && kept > 1e-3) {
    kept *= 0.5;
    shrunk = material::blend(unconstrained, nullptr, 1 - kept);
  }
  ASSERT_LT(kept, 1);
  // Relative RMS error against the data over every sample.
  const auto relative_error = [&](const material::RbfCorrection& c) {
    double e = 0, t = 0;
    for (Eigen::Index i = 0; i < samples.rows(); ++i) {
      const Vec3 s = samples.row(i).transpose();
      e += (c.correction(s, Vec3::Zero()) - target.correction(s, Vec3::Zero())).squaredNorm();
      t += target.correction(s, Vec3::Zero()).squaredNorm();
    }
    return std::sqrt(e / t);
  };
  EXPECT_LT(relative_error(stable), 0.35 * relative_error(shrunk))
      << "cut " << relative_error(stable) << ", shrunk to " << kept << ": "
      << relative_error(shrunk);
}

} // namespace
} // namespace elastolearn::learn
