// k-means++: finds well-separated clusters, is deterministic for a seed, validates input, and
// gives exactly the result of plain Lloyd (all n·k distances per iteration) despite its bounds.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/kmeans.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

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

// The accelerated assignment (Hamerly's bounds) must give exactly what plain Lloyd gives: the
// reference below is the previous implementation's Lloyd iterations, which computed all n·k
// distances every iteration, copied verbatim in its arithmetic (serial; its result never
// depended on threads). Both start from the same k-means++ centres: kmeans with
// max_iterations = 0 is the seeding alone.
namespace {

struct Reference {
  KMeansResult result;
  int reseeds = 0; ///< empty clusters re-seeded
  /// Re-seeds in an iteration that follows one without any (the accelerated code then
  /// assigned with live bounds just before).
  int late_reseeds = 0;
};

void reference_assign(
    const MatX& points_t, const MatX& centres_t, std::vector<int>& labels, VecX& distance) {
  const Eigen::Index d = points_t.rows();
  for (Eigen::Index i = 0; i < points_t.cols(); ++i) {
    const double* p = points_t.data() + i * d;
    double best = std::numeric_limits<double>::infinity();
    int label = 0;
    for (Eigen::Index c = 0; c < centres_t.cols(); ++c) {
      const double* q = centres_t.data() + c * d;
      double sum = 0;
      for (Eigen::Index j = 0; j < d; ++j) {
        const double diff = p[j] - q[j];
        sum += diff * diff;
      }
      if (sum < best) {
        best = sum;
        label = static_cast<int>(c);
      }
    }
    labels[i] = label;
    distance[i] = best;
  }
}

Reference reference_kmeans(const MatX& points, const KMeansOptions& options) {
  const Eigen::Index n = points.rows();
  const int k = options.clusters;
  const MatX points_t = points.transpose();
  KMeansOptions seeding = options;
  seeding.max_iterations = 0;
  Reference ref;
  KMeansResult& result = ref.result;
  result.centres = kmeans(points, seeding).centres;
  result.labels.assign(n, 0);
  VecX distance(n);
  const VecX mean = points_t.rowwise().mean();
  const double spread = std::sqrt((points_t.colwise() - mean).colwise().squaredNorm().mean());
  MatX sums(points.cols(), k);
  int last_reseed = -2;
  for (int it = 0; it < options.max_iterations; ++it) {
    reference_assign(points_t, result.centres.transpose(), result.labels, distance);
    sums.setZero();
    result.cluster_sizes = VecX::Zero(k);
    for (Eigen::Index i = 0; i < n; ++i) {
      sums.col(result.labels[i]) += points_t.col(i);
      result.cluster_sizes[result.labels[i]] += 1;
    }
    double shift = 0;
    for (int c = 0; c < k; ++c) {
      Eigen::RowVectorXd centre;
      if (result.cluster_sizes[c] > 0) {
        centre = sums.col(c).transpose() / result.cluster_sizes[c];
      } else {
        Eigen::Index far = 0;
        distance.maxCoeff(&far);
        centre = points.row(far);
        distance[far] = 0;
        ++ref.reseeds;
        ref.late_reseeds += it > 0 && last_reseed < it - 1;
        last_reseed = it;
      }
      shift = std::max(shift, (centre - result.centres.row(c)).norm());
      result.centres.row(c) = centre;
    }
    result.iterations = it + 1;
    if (shift <= options.tolerance * spread) {
      result.converged = true;
      break;
    }
  }
  reference_assign(points_t, result.centres.transpose(), result.labels, distance);
  result.cluster_sizes = VecX::Zero(k);
  for (Eigen::Index i = 0; i < n; ++i)
    result.cluster_sizes[result.labels[i]] += 1;
  result.inertia = distance.sum();
  return ref;
}

/// Run kmeans and the reference; every output must agree exactly. Returns the reference.
Reference expect_same_as_lloyd(const MatX& points, const KMeansOptions& options) {
  const KMeansResult got = kmeans(points, options);
  const Reference ref = reference_kmeans(points, options);
  const std::string what = "n = " + std::to_string(points.rows())
      + ", d = " + std::to_string(points.cols()) + ", k = " + std::to_string(options.clusters)
      + ", seed = " + std::to_string(options.seed);
  EXPECT_EQ(got.iterations, ref.result.iterations) << what;
  EXPECT_EQ(got.converged, ref.result.converged) << what;
  EXPECT_TRUE(got.labels == ref.result.labels) << what;
  EXPECT_TRUE(got.centres == ref.result.centres)
      << what << ", largest centre difference "
      << (got.centres - ref.result.centres).cwiseAbs().maxCoeff();
  EXPECT_TRUE(got.cluster_sizes == ref.result.cluster_sizes) << what;
  EXPECT_EQ(got.inertia, ref.result.inertia) << what;
  return ref;
}

/// Stretch-like samples: 1 + σ·N(0, 1) per coordinate, sorted descending within each point.
MatX sorted_stretches(Eigen::Index n, Eigen::Index d, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  MatX points(n, d);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::RowVectorXd row(d);
    for (Eigen::Index j = 0; j < d; ++j)
      row[j] = 1 + g(rng);
    std::sort(row.data(), row.data() + d, std::greater<>());
    points.row(i) = row;
  }
  return points;
}

MatX uniform_points(Eigen::Index n, Eigen::Index d, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX points(n, d);
  for (Eigen::Index i = 0; i < points.size(); ++i)
    points.data()[i] = u(rng);
  return points;
}

KMeansOptions options_for(int k, std::uint64_t seed, double tolerance = 1e-4) {
  KMeansOptions options;
  options.clusters = k;
  options.seed = seed;
  options.tolerance = tolerance;
  return options;
}

} // namespace

TEST(KMeans, MatchesPlainLloydOnStretchSamples) {
  const MatX points = sorted_stretches(4000, 3, 0.05, 11);
  for (const int k : { 1, 7, 40 })
    expect_same_as_lloyd(points, options_for(k, 5));
  // Tolerance 0 runs until no centre moves at all (or 100 iterations): the bounds age longest.
  expect_same_as_lloyd(points, options_for(40, 6, 0.0));
}

TEST(KMeans, MatchesPlainLloydOnUniformPoints) {
  for (const Eigen::Index d : { 3, 5 }) {
    const MatX points = uniform_points(3000, d, 12 + unsigned(d));
    for (const int k : { 1, 7, 40 })
      expect_same_as_lloyd(points, options_for(k, 7));
  }
}

TEST(KMeans, MatchesPlainLloydOnOverlappingBlobs) {
  // d = 5 (the generic path) and d = 6 (the unrolled one), blobs about half as wide as apart.
  for (const Eigen::Index d : { 5, 6 }) {
    MatX truth(12, d);
    truth.setRandom();
    const MatX points = blobs(truth, 250, 0.3, 21);
    for (const int k : { 7, 40 })
      expect_same_as_lloyd(points, options_for(k, 8, 0.0));
  }
}

TEST(KMeans, MatchesPlainLloydWithDuplicatesAndTies) {
  // Points on the integer grid {0, …, levels − 1}³, each repeated many times: centres often sit
  // on grid points or exactly midway, distances tie exactly, and labels rest on the
  // lowest-index rule (also when a point whose bounds fail meets a tie).
  for (const unsigned levels : { 3u, 4u }) {
    for (unsigned seed = 1; seed <= 8; ++seed) {
      std::mt19937 rng(seed);
      MatX points(1000, 3);
      for (Eigen::Index i = 0; i < points.size(); ++i)
        points.data()[i] = double(rng() % levels);
      for (const int k : { 1, 7, 20, 40 })
        expect_same_as_lloyd(points, options_for(k, seed, 0.0));
    }
  }
  // Stretch samples with every point present twice, the copies far apart in the order.
  MatX twice(4000, 3);
  twice << sorted_stretches(2000, 3, 0.05, 32), sorted_stretches(2000, 3, 0.05, 32);
  expect_same_as_lloyd(twice, options_for(40, 10));
}

TEST(KMeans, MatchesPlainLloydWhenAClusterEmpties) {
  // 15 distinct points and 20 clusters: seeding runs out of distinct points, duplicate
  // centres lose all points to the lower index, and are re-seeded.
  MatX few(40, 3);
  for (Eigen::Index i = 0; i < few.rows(); ++i)
    few.row(i) = Eigen::RowVector3d(double(i % 5), 0.5 * double(i % 3), 1.0);
  EXPECT_GT(expect_same_as_lloyd(few, options_for(20, 3)).reseeds, 0);
  // A cluster that empties later, after centres have moved, is rare; on these 48 points on a
  // line (found by search) about one seed in four makes it happen, and the worst-served
  // point is not the first. Require that it did.
  const std::vector<std::pair<double, int>> groups
      = { { 18, 7 }, { 21, 8 }, { 33, 12 }, { 8, 5 }, { 37, 4 }, { 38, 12 } }; // position, copies
  MatX line = MatX::Zero(48, 3);
  Eigen::Index row = 0;
  for (const auto& [x, copies] : groups) {
    for (int c = 0; c < copies; ++c)
      line(row++, 0) = x;
  }
  int late_reseeds = 0;
  for (unsigned seed = 1; seed <= 100; ++seed)
    late_reseeds += expect_same_as_lloyd(line, options_for(3, seed, 0.0)).late_reseeds;
  EXPECT_GT(late_reseeds, 0);
}
