// material_stability (issue 19, "stable corrections"): the nominal models are stable, a
// correction that removes more stiffness than the nominal has is found at the stretches where
// it does, and only there.
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace elastolearn::learn {
namespace {

const material::CorotatedModel k_nominal(material::Lame::from_young_poisson(1e5, 0.4));

MatX stretch_grid() {
  MatX s(0, 3);
  for (double a = 0.7; a <= 1.31; a += 0.1)
    for (double b = 0.7; b <= a + 1e-9; b += 0.1)
      for (double c = 0.7; c <= b + 1e-9; c += 0.1) {
        s.conservativeResize(s.rows() + 1, 3);
        s.row(s.rows() - 1) << a, b, c;
      }
  return s;
}

/// The linear tail N_k = a e_k + b(Σe − e_k): a Lamé change Δμ = (a − b)/2, Δλ = b.
material::RbfCorrection lame_change(double d_mu, double d_lambda) {
  material::RbfCorrection::Parameters p;
  p.centres.resize(0, 3);
  p.energy_kernels = true;
  p.own_slope = 2 * d_mu + d_lambda;
  p.other_slope = d_lambda;
  return material::RbfCorrection(std::move(p));
}

/// One energy kernel of weight w [Pa] and smoothing ε at `centre` (a softening for w < 0).
material::RbfCorrection one_kernel(const Vec3& centre, double weight, double epsilon) {
  material::RbfCorrection::Parameters p;
  p.energy_kernels = true;
  p.epsilon = epsilon;
  p.centres = centre.transpose();
  p.weights = VecX::Constant(1, weight);
  return material::RbfCorrection(std::move(p));
}

/// Isochoric uniaxial stretches σ = (s, s^-1/2, s^-1/2) for s = 1, 1 + ds, …, 1 + n·ds.
MatX isochoric_uniaxial(int n, double ds) {
  MatX out(n + 1, 3);
  for (int i = 0; i <= n; ++i) {
    const double s = 1 + ds * i;
    out.row(i) << s, 1 / std::sqrt(s), 1 / std::sqrt(s);
  }
  return out;
}

/// The largest ‖P̂(σ)‖ of `nominal` over the rows of `stretches`.
double largest_stress(const material::ElasticModel& nominal, const MatX& stretches) {
  double largest = 0;
  for (Eigen::Index i = 0; i < stretches.rows(); ++i)
    largest = std::max(largest, nominal.principal_stress(stretches.row(i).transpose()).norm());
  return largest;
}

/// The distance from `target` to the nearest row of `samples` (∞ if there is none).
double nearest_distance(const MatX& samples, const Vec3& target) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < samples.rows(); ++i)
    best = std::min(best, (samples.row(i).transpose() - target).norm());
  return best;
}

TEST(MaterialStability, NominalAndMildCorrectionsAreStable) {
  const MatX grid = stretch_grid();
  const StabilityReport nominal = material_stability(k_nominal, nullptr, grid);
  EXPECT_TRUE(nominal.stable());
  EXPECT_EQ(nominal.samples, grid.rows());
  EXPECT_NEAR(nominal.min_relative_eigenvalue, 1.0, 1e-12); // relative to itself
  const double mu = material::Lame::from_young_poisson(1e5, 0.4).mu;
  const material::RbfCorrection softer = lame_change(-0.5 * mu, 0);
  const StabilityReport r = material_stability(k_nominal, &softer, grid);
  EXPECT_TRUE(r.stable());
  // Twist 2μ → μ: half the nominal's smallest eigenvalue (2μ, the twist and the block's).
  EXPECT_NEAR(r.min_relative_eigenvalue, 0.5, 1e-9);
}

TEST(MaterialStability, FindsAShearInstability) {
  const double mu = material::Lame::from_young_poisson(1e5, 0.4).mu;
  const material::RbfCorrection too_soft = lame_change(-1.5 * mu, 0);
  const MatX grid = stretch_grid();
  const StabilityReport r = material_stability(k_nominal, &too_soft, grid);
  EXPECT_FALSE(r.stable());
  EXPECT_EQ(r.unstable_samples, grid.rows()); // a Lamé change acts everywhere alike
  EXPECT_NEAR(r.min_relative_eigenvalue, -0.5, 1e-9);
  // The message names the count and the least stable sample.
  const std::string text = describe_unstable(r, "samples");
  EXPECT_EQ(
      text.rfind("unstable at " + std::to_string(grid.rows()) + " of " + std::to_string(grid.rows())
              + " samples (stiffness -0.5 × the nominal's at σ = (",
          0),
      0u)
      << text;
}

TEST(MaterialStability, FindsALocalSofteningWhereItActs) {
  // One energy kernel at stretch (1.2, 1.2, 1.2): a softening there, none near rest.
  // Curvature 6 w/ε = −4e5 Pa at the centre (the nominal's smallest is 2μ = 7.1e4 Pa) and of
  // order 6 w/r = −3.5e4 Pa at rest, r = 0.35 away: the multiquadric's curvature decays as 1/r.
  const material::RbfCorrection local = one_kernel(Vec3(1.2, 1.2, 1.2), -2e3, 0.03);
  MatX near_rest(1, 3), near_centre(1, 3);
  near_rest << 1.0, 1.0, 1.0;
  near_centre << 1.2, 1.2, 1.2;
  EXPECT_TRUE(material_stability(k_nominal, &local, near_rest).stable());
  const StabilityReport r = material_stability(k_nominal, &local, near_centre);
  EXPECT_FALSE(r.stable());
  EXPECT_EQ(r.worst_stretches, Vec3(1.2, 1.2, 1.2));
}

TEST(MaterialStability, AmplifiedStretchesReachALargerMotionsInstability) {
  // Samples of an isochoric stretch (s, s^-1/2, s^-1/2), s ≤ 1.1, raised to the powers 1 and 2:
  // each row is exactly σᵃ (J stays 1), and the kernel softening at s = 1.2 of the test above is
  // reached only by the amplified samples (1.1² = 1.21).
  MatX motion(11, 3);
  for (int i = 0; i <= 10; ++i) {
    const double s = 1 + 0.01 * i;
    motion.row(i) << s, 1 / std::sqrt(s), 1 / std::sqrt(s);
  }
  const std::array<double, 2> powers { 1.0, 2.0 };
  const MatX amplified = amplified_stretches(motion, powers, 1000);
  ASSERT_EQ(amplified.rows(), 22);
  for (int i = 0; i <= 10; ++i) {
    EXPECT_EQ(amplified.row(i), motion.row(i));
    for (int c = 0; c < 3; ++c)
      EXPECT_DOUBLE_EQ(amplified(11 + i, c), motion(i, c) * motion(i, c));
    EXPECT_NEAR(amplified.row(11 + i).prod(), 1.0, 1e-14);
  }
  // The row cap keeps every ⌈2 · 11 / 10⌉ = 3rd sample of each power.
  EXPECT_EQ(amplified_stretches(motion, powers, 10).rows(), 8);

  const material::RbfCorrection local
      = one_kernel(Vec3(1.2, 1 / std::sqrt(1.2), 1 / std::sqrt(1.2)), -2e3, 0.03);
  EXPECT_TRUE(material_stability(k_nominal, &local, motion).stable());
  const StabilityReport r = material_stability(k_nominal, &local, amplified);
  EXPECT_FALSE(r.stable());
  EXPECT_GT(r.worst_stretches[0], 1.1);
}

TEST(MaterialStability, ReachableStretchesSpanOtherMotionsAtTheDatasStress) {
  // A nearly incompressible nominal (ν 0.45) stretched uniaxially, σ = (s, s^-1/2, s^-1/2) for
  // s ≤ 1.05: the reachable samples hold isochoric shears of the same magnitude (other kinds of
  // motion at the same stress) but not a uniform expansion to the data's largest stretch, whose
  // corotated stress λ(J − 1) ≈ 9μ · 0.125 is about 18 times the data's largest (≈ 2μ · 0.05).
  const material::CorotatedModel nominal(material::Lame::from_young_poisson(1e5, 0.45));
  const MatX uniaxial = isochoric_uniaxial(10, 0.005);
  const double largest = largest_stress(nominal, uniaxial);
  const double amplification = 1.25, spacing = 0.01;
  const MatX r = reachable_stretches(nominal, uniaxial, amplification, 2, spacing);
  ASSERT_GT(r.rows(), 0);
  const double low = std::pow(uniaxial.minCoeff(), amplification);
  const double high = std::pow(uniaxial.maxCoeff(), amplification);
  for (Eigen::Index i = 0; i < r.rows(); ++i) {
    const Vec3 s = r.row(i).transpose();
    EXPECT_GE(s(0), s(1));
    EXPECT_GE(s(1), s(2));
    EXPECT_GE(s(2), low - 1e-12);
    EXPECT_LE(s(0), high + 1e-12);
    EXPECT_LE(nominal.principal_stress(s).norm(), 2 * largest);
  }
  // The nearest sample to a pure shear (1.03, 1, 1/1.03) and to a uniform expansion 1.04³.
  EXPECT_LT(nearest_distance(r, Vec3(1.03, 1.0, 1 / 1.03)), spacing);
  EXPECT_GT(nearest_distance(r, Vec3(1.04, 1.04, 1.04)), 3 * spacing);
  // A kernel softening at the isochoric biaxial state (1.015, 1.015, 1/1.015²), ≥ 0.05 = 5ε from
  // every data sample: it removes about 0.7 of the nominal's stiffness there, 0.35 along the data.
  // Stable where the data went, it is found unstable where another motion may go.
  const material::RbfCorrection biaxial_softening
      = one_kernel(Vec3(1.015, 1.015, 1 / (1.015 * 1.015)), -4e2, 0.01);
  EXPECT_TRUE(material_stability(nominal, &biaxial_softening, uniaxial).stable());
  const StabilityReport reach = material_stability(nominal, &biaxial_softening, r);
  EXPECT_FALSE(reach.stable());
  EXPECT_LT((reach.worst_stretches - Vec3(1.015, 1.015, 1 / (1.015 * 1.015))).norm(), 2 * spacing);
  // Nothing to reach from no data, or from inverted elements only.
  EXPECT_EQ(reachable_stretches(nominal, MatX(0, 3), amplification, 2, spacing).rows(), 0);
  MatX inverted(1, 3);
  inverted << 1.1, 1.0, -0.2;
  EXPECT_EQ(reachable_stretches(nominal, inverted, amplification, 2, spacing).rows(), 0);
}

TEST(MaterialStability, ReachableStretchesChangeTheVolumeNoMoreThanTheData) {
  // A compressible nominal (ν 0.3) stretched isochorically to s = 1.3 reaches a stress at which
  // a uniform expansion of 20 % volume or more stays under the stress bound: the volume bound
  // must still leave it out, while shears of the data's magnitude stay in. Every sample's J is
  // within the data's J range (here 1) widened by one grid step of the 25-point grid.
  const material::CorotatedModel nominal(material::Lame::from_young_poisson(1e5, 0.3));
  const MatX isochoric = isochoric_uniaxial(30, 0.01);
  const double largest = largest_stress(nominal, isochoric);
  double expansion = 1; // the largest uniform stretch under the stress bound
  while (nominal.principal_stress(Vec3::Constant(expansion + 0.001)).norm() <= 2 * largest)
    expansion += 0.001;
  ASSERT_GT(std::pow(expansion, 3), 1.2); // the stress bound alone would keep it
  const MatX r = reachable_stretches(nominal, isochoric);
  ASSERT_GT(r.rows(), 0);
  const double low = std::pow(isochoric.minCoeff(), kReachableAmplification);
  const double high = std::pow(isochoric.maxCoeff(), kReachableAmplification);
  const double step = (high - low) / (kReachableMaxPoints - 1);
  for (Eigen::Index i = 0; i < r.rows(); ++i)
    EXPECT_NEAR(r.row(i).prod(), 1.0, step + 1e-12);
  EXPECT_GT(nearest_distance(r, Vec3::Constant(expansion)), 0.05);
  EXPECT_LT(nearest_distance(r, Vec3(1.2, 1.0, 1 / 1.2)), step);
}

} // namespace
} // namespace elastolearn::learn
