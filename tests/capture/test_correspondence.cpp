// Probabilistic correspondence (paper 000 Eq. 9): the weights against the formula on a tiny
// case, against brute force, independent of point order; surface samples; the position energy's
// gradient and Hessian against finite differences.
#include <elastolearn/capture/correspondence.hpp>
#include <elastolearn/core/error.hpp>

#include <support/finite_difference.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>

using namespace elastolearn;
using namespace elastolearn::capture;

namespace {

Positions random_points(int n, std::uint64_t seed, double scale) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Positions p(n, 3);
  for (Eigen::Index i = 0; i < p.size(); ++i)
    p.data()[i] = uniform(rng);
  return p;
}

/// A closed octahedron (6 vertices, 8 outward faces, 12 edges).
struct Octahedron {
  Positions x;
  Faces faces;
  Octahedron() {
    x.resize(6, 3);
    x << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
    faces.resize(8, 3);
    faces << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  }
};

} // namespace

TEST(Correspondence, WeightsMatchTheFormulaOnATinyCase) {
  // Two surface points, four cloud points at chosen distances; σ = 0.01, truncation 1e-3
  // (kept within 3.717 σ).
  Positions s(2, 3);
  s << 0, 0, 0, 1, 0, 0;
  Positions c(4, 3);
  c << 0.01, 0, 0, // 1 σ from s0
      0, 0.03, 0, // 3 σ from s0
      0, 0, 0.04, // 4 σ from s0: truncated (exp(−8) = 3.4e-4 < 1e-3)
      1, 0.02, 0; // 2 σ from s1
  CorrespondenceOptions options;
  options.sigma = 0.01;
  const CloudIndex index(c);
  const std::vector<Correspondence> pairs = find_correspondences(index, s, options);
  const double norm = std::pow(2 * std::numbers::pi * 1e-4, -1.5); // (2πσ²)^(−3/2)
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].sample, 0);
  EXPECT_EQ(pairs[0].point, 0);
  EXPECT_NEAR(pairs[0].weight / (norm * std::exp(-0.5)), 1, 1e-12);
  EXPECT_EQ(pairs[1].sample, 0);
  EXPECT_EQ(pairs[1].point, 1);
  EXPECT_NEAR(pairs[1].weight / (norm * std::exp(-4.5)), 1, 1e-12);
  EXPECT_EQ(pairs[2].sample, 1);
  EXPECT_EQ(pairs[2].point, 3);
  EXPECT_NEAR(pairs[2].weight / (norm * std::exp(-2.0)), 1, 1e-12);

  // Per-point normalisation: a point shared by two samples splits its unit weight.
  Positions two(2, 3);
  two << 0, 0, 0, 0.01, 0, 0;
  options.normalize_per_point = true;
  const auto shared = find_correspondences(CloudIndex(c.topRows(1)), two, options);
  ASSERT_EQ(shared.size(), 2u);
  EXPECT_NEAR(shared[0].weight + shared[1].weight, 1, 1e-15);
  // c0 is 1 σ from s0 and 0 from s1: weights ∝ exp(−½) and 1.
  EXPECT_NEAR(shared[0].weight, std::exp(-0.5) / (1 + std::exp(-0.5)), 1e-14);
}

TEST(Correspondence, FindsExactlyThePairsAboveTheTruncationAsBruteForceDoes) {
  const Positions cloud = random_points(3000, 1, 0.1);
  const Positions samples = random_points(400, 2, 0.1);
  CorrespondenceOptions options;
  options.sigma = 0.004;
  options.truncation = 1e-2;
  const auto pairs = find_correspondences(CloudIndex(cloud), samples, options);
  std::set<std::pair<int, Eigen::Index>> expected;
  for (int k = 0; k < samples.rows(); ++k)
    for (Eigen::Index n = 0; n < cloud.rows(); ++n) {
      const double d2 = (cloud.row(n) - samples.row(k)).squaredNorm();
      if (std::exp(-d2 / (2 * options.sigma * options.sigma)) >= options.truncation)
        expected.insert({ k, n });
    }
  ASSERT_GT(expected.size(), 100u);
  ASSERT_EQ(pairs.size(), expected.size());
  auto it = expected.begin();
  for (const Correspondence& p : pairs) { // sorted by (sample, point), as the set
    EXPECT_EQ(p.sample, it->first);
    EXPECT_EQ(p.point, it->second);
    ++it;
  }
}

TEST(Correspondence, DoesNotDependOnPointOrder) {
  const Positions cloud = random_points(2000, 3, 0.1);
  const Positions samples = random_points(300, 4, 0.1);
  std::vector<Eigen::Index> order(static_cast<std::size_t>(cloud.rows()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(5));
  Positions shuffled(cloud.rows(), 3);
  for (Eigen::Index i = 0; i < cloud.rows(); ++i)
    shuffled.row(i) = cloud.row(order[static_cast<std::size_t>(i)]);
  for (bool normalize : { false, true }) {
    CorrespondenceOptions options;
    options.sigma = 0.005;
    options.normalize_per_point = normalize;
    const auto a = find_correspondences(CloudIndex(cloud), samples, options);
    const auto b = find_correspondences(CloudIndex(shuffled), samples, options);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(a.size(), 50u);
    // The same (sample, original point) pairs with the same weights.
    std::vector<std::tuple<int, Eigen::Index, double>> mapped;
    for (const Correspondence& p : b)
      mapped.emplace_back(p.sample, order[static_cast<std::size_t>(p.point)], p.weight);
    std::sort(mapped.begin(), mapped.end());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].sample, std::get<0>(mapped[i]));
      EXPECT_EQ(a[i].point, std::get<1>(mapped[i]));
      EXPECT_NEAR(a[i].weight, std::get<2>(mapped[i]), 1e-12 * a[i].weight);
    }
  }
}

TEST(Correspondence, EmptyCloudConstrainsNothing) {
  CorrespondenceOptions options;
  options.sigma = 0.01;
  const Positions none(0, 3);
  const CloudIndex index(none);
  EXPECT_TRUE(find_correspondences(index, random_points(10, 6, 1), options).empty());
  EXPECT_EQ(index.median_spacing(), 0);
  const Octahedron o;
  const SurfaceSamples samples = sample_surface(o.faces, 2);
  Positions gradient;
  EXPECT_EQ(correspondence_energy(samples, o.x, none, {}, 0.01, &gradient), 0);
  EXPECT_EQ(gradient.rows(), 6);
  EXPECT_EQ(gradient.squaredNorm(), 0);
}

TEST(Correspondence, RejectsBadOptions) {
  const Positions p = random_points(5, 7, 1);
  const CloudIndex index(p);
  CorrespondenceOptions options;
  EXPECT_THROW(find_correspondences(index, p, options), InputError); // σ = 0
  options.sigma = 0.1;
  options.truncation = 1;
  EXPECT_THROW(find_correspondences(index, p, options), InputError);
  options.truncation = 0;
  EXPECT_THROW(find_correspondences(index, p, options), InputError);
}

TEST(SurfaceSamples, LatticeOfAClosedSurfaceHasEveryPointOnce) {
  const Octahedron o;
  for (int s : { 1, 2, 3, 5 }) {
    const SurfaceSamples samples = sample_surface(o.faces, s);
    // V + (s − 1) E + (s − 1)(s − 2)/2 F
    EXPECT_EQ(samples.num_samples(), 6 + (s - 1) * 12 + (s - 1) * (s - 2) / 2 * 8) << s;
    const Positions p = samples.positions(o.x);
    for (int k = 0; k < samples.num_samples(); ++k) {
      EXPECT_NEAR(samples.weights.row(k).sum(), 1, 1e-15);
      EXPECT_GE(samples.weights.row(k).minCoeff(), 0);
      // On the octahedron |x| + |y| + |z| = 1.
      EXPECT_NEAR(p.row(k).cwiseAbs().sum(), 1, 1e-14);
      for (int j = 0; j < k; ++j)
        ASSERT_GT((p.row(k) - p.row(j)).norm(), 0.5 * std::sqrt(2.0) / s - 1e-12) << s;
    }
  }
  EXPECT_THROW(sample_surface(o.faces, 0), InputError);
  // Edge length √2: spacing 0.5 needs s = 3, spacing 2 needs s = 1.
  EXPECT_EQ(subdivision_for_spacing(o.x, o.faces, 0.5), 3);
  EXPECT_EQ(subdivision_for_spacing(o.x, o.faces, 2.0), 1);
}

TEST(Correspondence, BarycentricSamplesMatchACloudTheVerticesMiss) {
  // A cloud on the octahedron's face centres: 0.58 from every vertex, so with σ = 0.05 the
  // vertices alone find nothing, the s = 3 lattice (which has the face centre) finds each point.
  const Octahedron o;
  Positions centres(8, 3);
  for (int f = 0; f < 8; ++f)
    centres.row(f) = (o.x.row(o.faces(f, 0)) + o.x.row(o.faces(f, 1)) + o.x.row(o.faces(f, 2))) / 3;
  CorrespondenceOptions options;
  options.sigma = 0.05;
  const CloudIndex index(centres);
  EXPECT_TRUE(
      find_correspondences(index, sample_surface(o.faces, 1).positions(o.x), options).empty());
  const auto pairs
      = find_correspondences(index, sample_surface(o.faces, 3).positions(o.x), options);
  EXPECT_EQ(pairs.size(), 8u);
  EXPECT_NEAR(index.median_spacing(), std::sqrt(2.0) / 3 * std::sqrt(2.0), 1e-12);
}

TEST(Correspondence, EnergyGradientAndHessianMatchFiniteDifferences) {
  const Octahedron o;
  Positions x = o.x + 0.05 * random_points(6, 8, 1);
  const SurfaceSamples samples = sample_surface(o.faces, 3);
  const Positions cloud
      = 1.02 * samples.positions(x) + 0.03 * random_points(samples.num_samples(), 9, 1);
  CorrespondenceOptions options;
  options.sigma = 0.05;
  const auto pairs = find_correspondences(CloudIndex(cloud), samples.positions(x), options);
  ASSERT_GT(pairs.size(), 20u);
  const auto energy = [&](const VecX& flat) {
    return correspondence_energy(samples, unflatten(flat), cloud, pairs, options.sigma);
  };
  Positions gradient;
  const double e = correspondence_energy(samples, x, cloud, pairs, options.sigma, &gradient);
  EXPECT_GT(e, 0);
  const VecX fd = test::fd_gradient(energy, flatten(x), 1e-4);
  EXPECT_LT((flatten(gradient) - fd).cwiseAbs().maxCoeff(), 1e-7 * fd.cwiseAbs().maxCoeff());
  // The Hessian H ⊗ I₃ against differences of the gradient.
  const Eigen::MatrixXd H
      = Eigen::MatrixXd(correspondence_hessian(samples, 6, pairs, options.sigma));
  EXPECT_LT((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-12 * H.cwiseAbs().maxCoeff());
  const auto grad = [&](const VecX& flat) {
    Positions g;
    correspondence_energy(samples, unflatten(flat), cloud, pairs, options.sigma, &g);
    return VecX(flatten(g));
  };
  const Eigen::MatrixXd J = test::fd_jacobian(grad, flatten(x), 1e-4);
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(18, 18);
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b)
      full.block<3, 3>(3 * a, 3 * b) = H(a, b) * Eigen::Matrix3d::Identity();
  EXPECT_LT((full - J).cwiseAbs().maxCoeff(), 1e-7 * J.cwiseAbs().maxCoeff());
}
