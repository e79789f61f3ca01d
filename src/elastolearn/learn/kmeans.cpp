#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/kmeans.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>

namespace elastolearn::learn {

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

/// Squared distance of two d-vectors (D = d, or 0 for any d), summed in coordinate order. Every
/// distance in this file goes through here, so a distance recomputed later is bitwise the same.
template <int D> double squared_distance(const double* p, const double* q, Eigen::Index d) {
  double sum = 0;
  for (Eigen::Index j = 0; j < (D > 0 ? D : d); ++j) {
    const double diff = p[j] - q[j];
    sum += diff * diff;
  }
  return sum;
}

/// Run `f(std::integral_constant<int, D>)` with D = d for the common dimensions (an unrolled
/// inner loop), else with D = 0.
template <typename F> void with_dimension(Eigen::Index d, F&& f) {
  switch (d) {
  case 3:
    return f(std::integral_constant<int, 3> {});
  case 6:
    return f(std::integral_constant<int, 6> {});
  default:
    return f(std::integral_constant<int, 0> {});
  }
}

struct Nearest {
  int label = 0; ///< nearest centre (ties: lowest index)
  double best = infinity; ///< its squared distance
  double second = infinity; ///< squared distance to the nearest other centre (∞ if k = 1)
};

/// Nearest centre of the point p among the columns of the d × k `centres_t`.
template <int D> Nearest nearest(const double* p, const MatX& centres_t) {
  const Eigen::Index d = centres_t.rows();
  Nearest r;
  for (Eigen::Index c = 0; c < centres_t.cols(); ++c) {
    const double sum = squared_distance<D>(p, centres_t.data() + c * d, d);
    if (sum < r.best) {
      r.second = r.best;
      r.best = sum;
      r.label = static_cast<int>(c);
    } else {
      r.second = std::min(r.second, sum);
    }
  }
  return r;
}

/// Parallel loop over the n points; `body(i, p)` gets the index and the point's coordinates.
/// Each point's result depends only on that point, never on the thread split.
template <typename Body> void for_each_point(const MatX& points_t, Body&& body) {
  const Eigen::Index d = points_t.rows();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, points_t.cols(), 4096),
      [&](const tbb::blocked_range<Eigen::Index>& range) {
        for (Eigen::Index i = range.begin(); i != range.end(); ++i)
          body(i, points_t.data() + i * d);
      });
}

/// Sum of the points of each cluster (columns of the d × k `sums`) and the cluster sizes,
/// accumulated in point order so that the centres do not depend on anything else.
template <int D>
void cluster_sums(const MatX& points_t, const std::vector<int>& labels, MatX& sums, VecX& sizes) {
  const Eigen::Index d = points_t.rows();
  sums.setZero();
  sizes.setZero();
  for (Eigen::Index i = 0; i < points_t.cols(); ++i) {
    const double* p = points_t.data() + i * d;
    double* sum = sums.data() + labels[i] * d;
    for (Eigen::Index j = 0; j < (D > 0 ? D : d); ++j)
      sum[j] += p[j];
    sizes[labels[i]] += 1;
  }
}

/// Squared distance of every point to the centre it is labelled with.
template <int D>
void labelled_distances(
    const MatX& points_t, const MatX& centres_t, const std::vector<int>& labels, VecX& distance) {
  const Eigen::Index d = points_t.rows();
  for_each_point(points_t, [&](Eigen::Index i, const double* p) {
    distance[i] = squared_distance<D>(p, centres_t.data() + labels[i] * d, d);
  });
}

/// Lloyd's assignment step accelerated with Hamerly's bounds ("Making k-means even faster",
/// SDM 2010), because it is the hot path: plain Lloyd computes all n·k distances every
/// iteration. Per point, an upper bound on the distance to its centre and one lower bound on
/// the distance to every other centre (moved by the centre shifts) prove that most points keep
/// their centre. A point whose bounds fail visits the other centres by increasing gap from its
/// own and stops once the triangle inequality puts the rest beyond the second-nearest: the
/// same nearest and second-nearest as comparing all k, for a fraction of the distances.
/// Exactness: bounds are on plain distances, upper ones rounded up and lower ones down by
/// `slack`, and a centre is only ruled out by a relative margin of `slack`, far above the
/// rounding of a squared distance; so labels equal plain Lloyd's, lowest-index ties included.
class HamerlyAssignment {
  public:
  HamerlyAssignment(Eigen::Index n, Eigen::Index d, int k)
      : m_upper(n)
      , m_lower(n)
      , m_shift(VecX::Zero(k))
      , m_gap(k, k)
      , m_order(k - 1, k)
      , m_slack(16 * double(d + 10) * std::numeric_limits<double>::epsilon()) { }

  /// Label every point with its nearest centre (columns of the d × k `centres_t`). `labels`
  /// must hold the previous labels unless the bounds were invalidated.
  template <int D>
  void assign(const MatX& points_t, const MatX& centres_t, std::vector<int>& labels);

  /// Record how far centre c moved since the last `assign`.
  void set_shift(int c, double distance) { m_shift[c] = distance; }
  /// Forget the bounds: the next `assign` compares every point with all centres (as on first
  /// use; after a re-seed, where a centre jumps).
  void invalidate() { m_valid = false; }

  private:
  double up(double x) const { return x * (1 + m_slack); }
  double down(double x) const { return x * (1 - m_slack); }
  /// ≤ half the distance of centre a to its nearest other centre (∞ for one centre).
  double half_gap(int a) const {
    return m_order.rows() > 0 ? 0.5 * m_gap(m_order(0, a), a) : infinity;
  }
  template <int D> void update_gaps(const MatX& centres_t);
  template <int D>
  Nearest nearest_around(
      const double* p, const MatX& centres_t, int a, double best, double upper) const;

  VecX m_upper; ///< n: ≥ distance of each point to its labelled centre
  VecX m_lower; ///< n: ≤ distance of each point to every other centre
  VecX m_shift; ///< k: distance each centre moved since the last assign
  MatX m_gap; ///< k × k: ≤ distance between two centres
  Eigen::MatrixXi m_order; ///< (k − 1) × k: column a = the other centres by increasing gap from a
  double m_slack; ///< 16 × the relative rounding of a squared distance, about (d + 3) ε
  bool m_valid = false; ///< false: m_upper and m_lower mean nothing
};

template <int D> void HamerlyAssignment::update_gaps(const MatX& centres_t) {
  const Eigen::Index d = centres_t.rows();
  const int k = static_cast<int>(centres_t.cols());
  for (int a = 0; a < k; ++a) {
    m_gap(a, a) = 0;
    for (int b = a + 1; b < k; ++b) {
      m_gap(a, b) = m_gap(b, a) = down(
          std::sqrt(squared_distance<D>(centres_t.data() + a * d, centres_t.data() + b * d, d)));
    }
  }
  for (int a = 0; a < k; ++a) {
    int* order = m_order.col(a).data();
    for (int c = 0, row = 0; c < k; ++c) {
      if (c != a)
        order[row++] = c;
    }
    std::sort(order, order + k - 1, [&](int b, int c) { // ties by index: deterministic
      return m_gap(b, a) < m_gap(c, a) || (m_gap(b, a) == m_gap(c, a) && b < c);
    });
  }
}

/// Nearest centre of the point p labelled a, given `best` = its squared distance to centre a
/// and `upper` ≥ the plain distance.
template <int D>
Nearest HamerlyAssignment::nearest_around(
    const double* p, const MatX& centres_t, int a, double best, double upper) const {
  const Eigen::Index d = centres_t.rows();
  Nearest r { a, best, infinity };
  for (Eigen::Index row = 0; row < m_order.rows(); ++row) {
    const int c = m_order(row, a);
    const double rest = down(m_gap(c, a) - upper); // ≤ distance of p to c and all after it
    if (rest > 0 && down(rest * rest) > r.second)
      break;
    const double sum = squared_distance<D>(p, centres_t.data() + c * d, d);
    if (sum < r.best || (sum == r.best && c < r.label)) { // Lloyd's rule: lowest index wins
      r.second = r.best;
      r.best = sum;
      r.label = c;
    } else {
      r.second = std::min(r.second, sum);
    }
  }
  return r;
}

template <int D>
void HamerlyAssignment::assign(
    const MatX& points_t, const MatX& centres_t, std::vector<int>& labels) {
  const Eigen::Index d = points_t.rows();
  if (!m_valid) {
    for_each_point(points_t, [&](Eigen::Index i, const double* p) {
      const Nearest near = nearest<D>(p, centres_t);
      labels[i] = near.label;
      m_upper[i] = up(std::sqrt(near.best));
      m_lower[i] = down(std::sqrt(near.second));
    });
    m_valid = true;
    return;
  }
  update_gaps<D>(centres_t);
  // A lower bound drops by the largest shift of the other centres: the largest overall, or
  // the second largest for points labelled with the centre that moved most.
  Eigen::Index most = 0;
  const double largest = up(m_shift.maxCoeff(&most));
  double second = 0;
  for (Eigen::Index c = 0; c < m_shift.size(); ++c)
    second = c == most ? second : std::max(second, m_shift[c]);
  second = up(second);
  for_each_point(points_t, [&](Eigen::Index i, const double* p) {
    const int a = labels[i];
    double upper = up(m_upper[i] + m_shift[a]);
    double lower = down(m_lower[i]) - (a == most ? second : largest);
    // Within half the gap to its nearest other centre, or below the lower bound, a point
    // keeps its centre.
    const double bound = std::max(half_gap(a), lower);
    if (up(upper) >= bound) { // the upper bound may be loose: measure the distance
      const double own = squared_distance<D>(p, centres_t.data() + a * d, d);
      upper = up(std::sqrt(own));
      if (up(upper) >= bound) { // another centre may be as near
        const Nearest near = nearest_around<D>(p, centres_t, a, own, upper);
        labels[i] = near.label;
        upper = up(std::sqrt(near.best));
        lower = down(std::sqrt(near.second));
      }
    }
    m_upper[i] = upper;
    m_lower[i] = lower;
  });
}

/// k-means++ seeding on the d × n points; returns k × d centres.
MatX seed_centres(const MatX& points_t, int k, std::mt19937_64& rng) {
  const Eigen::Index n = points_t.cols();
  const Eigen::Index d = points_t.rows();
  MatX centres(k, d);
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
    for_each_point(points_t, [&](Eigen::Index i, const double* p) {
      candidate[i] = squared_distance<0>(p, centre.data(), d);
    });
    nearest = c == 0 ? candidate : nearest.cwiseMin(candidate);
  }
  return centres;
}

} // namespace

void KMeansOptions::validate() const {
  if (clusters < 1)
    throw InputError("kmeans.clusters", "must be at least 1, got " + to_text(clusters));
  if (max_iterations < 0)
    throw InputError("kmeans.max_iterations", "must be ≥ 0, got " + to_text(max_iterations));
  if (!(tolerance >= 0) || !std::isfinite(tolerance))
    throw InputError("kmeans.tolerance", "must be finite and ≥ 0, got " + to_text(tolerance));
}

KMeansResult kmeans(ConstRef<MatX> points, const KMeansOptions& options) {
  options.validate();
  const Eigen::Index n = points.rows();
  const Eigen::Index d = points.cols();
  const int k = options.clusters;
  if (n < k) {
    throw InputError("kmeans.clusters",
        to_text(k) + " clusters need at least as many points, got " + to_text(n));
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

  // Everything the iterations touch is allocated here, once.
  MatX centres_t = result.centres.transpose(); // d × k, column c = centre c
  MatX sums(d, k); // column c = sum of the points of cluster c
  Eigen::RowVectorXd centre(d);
  result.cluster_sizes = VecX::Zero(k);
  HamerlyAssignment assignment(n, d, k);
  for (int it = 0; it < options.max_iterations; ++it) {
    with_dimension(d, [&](auto D) {
      assignment.assign<decltype(D)::value>(points_t, centres_t, result.labels);
      cluster_sums<decltype(D)::value>(points_t, result.labels, sums, result.cluster_sizes);
    });
    if (result.cluster_sizes.minCoeff() == 0) {
      // Re-seeding needs every point's distance; a re-seeded centre jumps, so start afresh.
      with_dimension(d, [&](auto D) {
        labelled_distances<decltype(D)::value>(points_t, centres_t, result.labels, distance);
      });
      assignment.invalidate();
    }
    double shift = 0;
    for (int c = 0; c < k; ++c) {
      if (result.cluster_sizes[c] > 0) {
        centre = sums.col(c).transpose() / result.cluster_sizes[c];
      } else { // re-seed an empty cluster at the worst-served point
        Eigen::Index far = 0;
        distance.maxCoeff(&far);
        centre = points.row(far);
        distance[far] = 0;
      }
      const double moved = (centre - result.centres.row(c)).norm();
      assignment.set_shift(c, moved);
      shift = std::max(shift, moved);
      result.centres.row(c) = centre;
    }
    centres_t = result.centres.transpose();
    result.iterations = it + 1;
    if (shift <= options.tolerance * spread) {
      result.converged = true;
      break;
    }
  }
  // Final labels for the final centres (the bounds still hold after the last update), then
  // the exact squared distances for the inertia.
  with_dimension(d, [&](auto D) {
    assignment.assign<decltype(D)::value>(points_t, centres_t, result.labels);
    labelled_distances<decltype(D)::value>(points_t, centres_t, result.labels, distance);
  });
  result.cluster_sizes.setZero();
  for (Eigen::Index i = 0; i < n; ++i)
    result.cluster_sizes[result.labels[i]] += 1;
  result.inertia = distance.sum();
  return result;
}

} // namespace elastolearn::learn
