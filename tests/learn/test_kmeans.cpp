// k-means++: finds well-separated clusters, is deterministic for a seed, and validates input.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/kmeans.hpp>

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// `per` points around each of the given centres, Gaussian with std `spread`, interleaved so
/// that cluster membership is not the point order.
MatX blobs(const MatX& centres, int per, double spread, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, spread);
  MatX points(centres.rows() * per, centres.cols());
  for (int i = 0; i < per; ++i) {
    for (Eigen::Index c = 0; c < centres.rows(); ++c) {
      for (Eigen::Index d = 0; d < centres.cols(); ++d)
        points(i * centres.rows() + c, d) = centres(c, d) + g(rng);
    }
  }
  return points;
}

} // namespace

TEST(KMeans, FindsSeparatedClusters) {
  // Five stretch-like clusters in R^3 (d = 3) separated by ≥ 0.2, spread 0.01: 20 σ apart.
  MatX truth(5, 3);
  truth << 1.0, 1.0, 1.0, 1.2, 1.0, 0.9, 0.8, 0.8, 0.8, 1.1, 1.3, 1.0, 0.9, 1.1, 1.2;
  const MatX points = blobs(truth, 200, 0.01, 3);
  KMeansOptions options;
  options.clusters = 5;
  options.seed = 4;
  const KMeansResult result = kmeans(points, options);
  EXPECT_TRUE(result.converged);
  std::set<int> matched;
  for (Eigen::Index c = 0; c < truth.rows(); ++c) {
    Eigen::Index best = 0;
    const double distance
        = (result.centres.rowwise() - truth.row(c)).rowwise().norm().minCoeff(&best);
    // The mean of 200 samples of std 0.01 lies within ~0.01/√200·√3 ≈ 1.2e-3 of the truth.
    EXPECT_LT(distance, 5e-3) << "cluster " << c;
    matched.insert(int(best));
  }
  EXPECT_EQ(matched.size(), 5u); // one centre per cluster
  // Points of one blob share a label: points c, c + 5, c + 10, ... came from blob c.
  for (Eigen::Index i = 5; i < points.rows(); ++i)
    EXPECT_EQ(result.labels[i], result.labels[i % 5]) << i;
  EXPECT_EQ(result.cluster_sizes, VecX::Constant(5, 200));
  // Inertia ≈ N·d·σ² = 1000·3·1e-4 = 0.3 (within 20 %).
  EXPECT_NEAR(result.inertia, 0.3, 0.06);
}

TEST(KMeans, DeterministicForASeed) {
  MatX truth(3, 6);
  truth.setRandom();
  const MatX points = blobs(truth, 50, 0.3, 8); // overlapping: the result depends on the seeding
  KMeansOptions options;
  options.clusters = 7;
  options.seed = 99;
  const KMeansResult a = kmeans(points, options), b = kmeans(points, options);
  EXPECT_EQ(a.centres, b.centres);
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.inertia, b.inertia);
  for (Eigen::Index c = 0; c < 7; ++c)
    EXPECT_GE(a.cluster_sizes[c], 1) << c;
  // Lloyd iterations never increase the inertia: more iterations, no worse a result.
  options.max_iterations = 0;
  EXPECT_GE(kmeans(points, options).inertia, a.inertia);
}

TEST(KMeans, OneClusterPerPointIsExact) {
  MatX points(4, 2);
  points << 0, 0, 1, 0, 0, 1, 5, 5;
  KMeansOptions options;
  options.clusters = 4;
  const KMeansResult r = kmeans(points, options);
  EXPECT_EQ(r.inertia, 0.0);
  EXPECT_EQ(std::set<int>(r.labels.begin(), r.labels.end()).size(), 4u);
}

TEST(KMeans, RejectsBadInput) {
  KMeansOptions options;
  options.clusters = 5;
  EXPECT_THROW(kmeans(MatX::Zero(3, 2), options), InputError); // fewer points than clusters
  MatX nan = MatX::Zero(10, 2);
  nan(3, 1) = std::nan("");
  EXPECT_THROW(kmeans(nan, options), InputError);
  options.clusters = 0;
  EXPECT_THROW(kmeans(MatX::Zero(10, 2), options), InputError);
}
