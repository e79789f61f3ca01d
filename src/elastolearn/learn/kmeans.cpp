#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/kmeans.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>

namespace elastolearn::learn {

namespace {

template <typename T> std::string str(T v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Label and squared distance of every point to its nearest centre (ties: lowest index).
/// `points_t` and `centres_t` are d × n and d × k (column-major: each point contiguous); the
/// distance of a point does not depend on how the range is split, so the result is deterministic.
template <int D>
void assign_fixed(
    const MatX& points_t, const MatX& centres_t, std::vector<int>& labels, VecX& distance) {
  const Eigen::Index n = points_t.cols();
  const Eigen::Index k = centres_t.cols();
  const Eigen::Index d = points_t.rows();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 4096),
      [&](const tbb::blocked_range<Eigen::Index>& range) {
        for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
          const double* p = points_t.data() + i * d;
          double best = std::numeric_limits<double>::infinity();
          int label = 0;
          for (Eigen::Index c = 0; c < k; ++c) {
            const double* q = centres_t.data() + c * d;
            double sum = 0;
            for (Eigen::Index j = 0; j < (D > 0 ? D : d); ++j) {
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
      });
}

void assign(const MatX& points_t, const MatX& centres_t, std::vector<int>& labels, VecX& distance) {
  switch (points_t.rows()) { // the common dimensions get an unrolled inner loop
  case 3:
    return assign_fixed<3>(points_t, centres_t, labels, distance);
  case 6:
    return assign_fixed<6>(points_t, centres_t, labels, distance);
  default:
    return assign_fixed<0>(points_t, centres_t, labels, distance);
  }
}

/// Squared distance of every point (columns of the d × n `points_t`) to `centre` (length d).
void squared_distances(const MatX& points_t, const VecX& centre, VecX& out) {
  const Eigen::Index d = points_t.rows();
  for (Eigen::Index i = 0; i < points_t.cols(); ++i) {
    const double* p = points_t.data() + i * d;
    double sum = 0;
    for (Eigen::Index j = 0; j < d; ++j)
      sum += (p[j] - centre[j]) * (p[j] - centre[j]);
    out[i] = sum;
  }
}

/// k-means++ seeding on the d × n points; returns k × d centres.
MatX seed_centres(const MatX& points_t, int k, std::mt19937_64& rng) {
  const Eigen::Index n = points_t.cols();
  MatX centres(k, points_t.rows());
  std::uniform_int_distribution<Eigen::Index> uniform(0, n - 1);
  VecX nearest(n), candidate(n);
  for (int c = 0; c < k; ++c) {
    Eigen::Index pick = 0;
    const double total = c == 0 ? 0.0 : nearest.sum();
    if (total > 0) {
      const double target = std::uniform_real_distribution<double>(0.0, total)(rng);
      double cumulative = 0;
      pick = -1;
      for (Eigen::Index i = 0; i < n; ++i) {
        cumulative += nearest[i];
        if (cumulative > target && nearest[i] > 0) {
          pick = i;
          break;
        }
      }
      if (pick < 0) { // rounding at the end of the sum: take the last point that has weight
        for (pick = n - 1; pick > 0 && nearest[pick] <= 0; --pick) { }
      }
    } else {
      pick = uniform(rng); // first centre, or all points coincide with chosen centres
    }
    const VecX centre = points_t.col(pick);
    centres.row(c) = centre.transpose();
    squared_distances(points_t, centre, candidate);
    nearest = c == 0 ? candidate : nearest.cwiseMin(candidate);
  }
  return centres;
}

} // namespace

void KMeansOptions::validate() const {
  if (clusters < 1)
    throw InputError("kmeans.clusters", "must be at least 1, got " + str(clusters));
  if (max_iterations < 0)
    throw InputError("kmeans.max_iterations", "must be ≥ 0, got " + str(max_iterations));
  if (!(tolerance >= 0) || !std::isfinite(tolerance))
    throw InputError("kmeans.tolerance", "must be finite and ≥ 0, got " + str(tolerance));
}

KMeansResult kmeans(ConstRef<MatX> points, const KMeansOptions& options) {
  options.validate();
  const Eigen::Index n = points.rows();
  const int k = options.clusters;
  if (n < k) {
    throw InputError(
        "kmeans.clusters", str(k) + " clusters need at least as many points, got " + str(n));
  }
  if (!points.allFinite())
    throw InputError("kmeans", "points contain a non-finite value");

  const MatX points_t = points.transpose();
  std::mt19937_64 rng(options.seed);
  KMeansResult result;
  result.centres = seed_centres(points_t, k, rng);
  result.labels.assign(n, 0);
  VecX distance(n);
  // RMS distance of the points from their mean (the mean is evaluated once, not per row).
  const VecX mean = points_t.rowwise().mean();
  const double spread = std::sqrt((points_t.colwise() - mean).colwise().squaredNorm().mean());

  MatX sums(points.cols(), k); // d × k, column c = sum of the points of cluster c
  for (int it = 0; it < options.max_iterations; ++it) {
    assign(points_t, result.centres.transpose(), result.labels, distance);
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
      } else { // re-seed an empty cluster at the worst-served point
        Eigen::Index far = 0;
        distance.maxCoeff(&far);
        centre = points.row(far);
        distance[far] = 0;
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
  assign(points_t, result.centres.transpose(), result.labels, distance);
  result.cluster_sizes = VecX::Zero(k);
  for (Eigen::Index i = 0; i < n; ++i)
    result.cluster_sizes[result.labels[i]] += 1;
  result.inertia = distance.sum();
  return result;
}

} // namespace elastolearn::learn
