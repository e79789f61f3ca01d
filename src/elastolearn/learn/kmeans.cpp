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
void assign(ConstRef<MatX> points, const MatX& centres, std::vector<int>& labels, VecX& distance) {
  const Eigen::Index n = points.rows();
  const Eigen::Index k = centres.rows();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 1024),
      [&](const tbb::blocked_range<Eigen::Index>& range) {
        for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
          double best = std::numeric_limits<double>::infinity();
          int label = 0;
          for (Eigen::Index c = 0; c < k; ++c) {
            const double d = (points.row(i) - centres.row(c)).squaredNorm();
            if (d < best) {
              best = d;
              label = static_cast<int>(c);
            }
          }
          labels[i] = label;
          distance[i] = best;
        }
      });
}

/// k-means++ seeding.
MatX seed_centres(ConstRef<MatX> points, int k, std::mt19937_64& rng) {
  const Eigen::Index n = points.rows();
  MatX centres(k, points.cols());
  std::uniform_int_distribution<Eigen::Index> uniform(0, n - 1);
  centres.row(0) = points.row(uniform(rng));
  VecX nearest = (points.rowwise() - centres.row(0)).rowwise().squaredNorm();
  for (int c = 1; c < k; ++c) {
    const double total = nearest.sum();
    Eigen::Index pick = 0;
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
      pick = uniform(rng); // all points coincide with chosen centres
    }
    centres.row(c) = points.row(pick);
    nearest = nearest.cwiseMin((points.rowwise() - centres.row(c)).rowwise().squaredNorm());
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
    throw InputError("kmeans.clusters",
        str(k) + " clusters need at least as many points, got " + str(n));
  }
  if (!points.allFinite())
    throw InputError("kmeans", "points contain a non-finite value");

  std::mt19937_64 rng(options.seed);
  KMeansResult result;
  result.centres = seed_centres(points, k, rng);
  result.labels.assign(n, 0);
  VecX distance(n);
  const double spread = std::sqrt(
      (points.rowwise() - points.colwise().mean()).rowwise().squaredNorm().mean());

  MatX sums(k, points.cols());
  for (int it = 0; it < options.max_iterations; ++it) {
    assign(points, result.centres, result.labels, distance);
    sums.setZero();
    result.cluster_sizes = VecX::Zero(k);
    for (Eigen::Index i = 0; i < n; ++i) {
      sums.row(result.labels[i]) += points.row(i);
      result.cluster_sizes[result.labels[i]] += 1;
    }
    double shift = 0;
    for (int c = 0; c < k; ++c) {
      Eigen::RowVectorXd centre;
      if (result.cluster_sizes[c] > 0) {
        centre = sums.row(c) / result.cluster_sizes[c];
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
  assign(points, result.centres, result.labels, distance);
  result.cluster_sizes = VecX::Zero(k);
  for (Eigen::Index i = 0; i < n; ++i)
    result.cluster_sizes[result.labels[i]] += 1;
  result.inertia = distance.sum();
  return result;
}

} // namespace elastolearn::learn
