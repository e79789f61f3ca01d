#pragma once
/// \file k-means clustering with k-means++ seeding (Arthur & Vassilvitskii 2007), used to choose
/// the RBF centres F_i among the element/frame stretch samples (paper 000 §6.1, Eq. 10).
#include <elastolearn/core/types.hpp>

#include <cstdint>
#include <vector>

namespace elastolearn::learn {

struct KMeansOptions {
  int clusters = 40; ///< k ≥ 1
  std::uint64_t seed = 1; ///< seeds std::mt19937_64 for the k-means++ draws
  int max_iterations = 100; ///< Lloyd iterations at most (≥ 0; 0 = seeding only)
  /// Stop when no centre moves by more than tolerance × (RMS spread of the points about their
  /// mean). RBF centres need no more than ~1e-4: Lloyd creeps on for hundreds of iterations on
  /// evenly spread samples without changing the clustering materially.
  double tolerance = 1e-4;
  /// Throws InputError("kmeans.<field>", ...) for an out-of-range field.
  void validate() const;
};

struct KMeansResult {
  MatX centres; ///< k × d
  std::vector<int> labels; ///< nearest centre of each point (n)
  VecX cluster_sizes; ///< points per centre (k), all ≥ 1 when there are ≥ k distinct points
  double inertia = 0; ///< Σ ‖x − c(x)‖² over all points
  int iterations = 0; ///< Lloyd iterations run
  bool converged = false; ///< stopped by the tolerance (not by max_iterations)
};

/// Cluster the rows of `points` (n × d, n ≥ k, finite). Deterministic: same points, options and
/// seed give the same result (the assignment step runs in parallel but each point's result does
/// not depend on the thread; sums are taken in point order). k-means++ seeding: the first centre
/// uniformly, each next one with probability ∝ squared distance to the nearest chosen centre.
/// A cluster that empties is re-seeded at the point farthest from its centre.
/// Throws InputError if n < k, the points are not finite, or the options are invalid.
KMeansResult kmeans(ConstRef<MatX> points, const KMeansOptions& options);

} // namespace elastolearn::learn
