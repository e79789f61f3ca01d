#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/observation_noise.hpp>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace elastolearn::observe {

namespace {

/// Frames × (3k) matrix of the observed coordinates: column 3j + c is vertex j's coordinate c.
MatX coordinate_series(const Observation& observed) {
  const auto frames = static_cast<Eigen::Index>(observed.num_frames());
  const auto k = static_cast<Eigen::Index>(observed.num_observed());
  MatX x(frames, 3 * k);
  for (Eigen::Index t = 0; t < frames; ++t)
    for (Eigen::Index j = 0; j < k; ++j)
      x.block<1, 3>(t, 3 * j) = observed.positions[static_cast<size_t>(t)].row(j);
  return x;
}

/// Binomial coefficients of the k-th difference, (−1)^(k−i) C(k, i).
std::vector<double> difference_stencil(int order) {
  std::vector<double> c(static_cast<size_t>(order) + 1, 0.0);
  c[0] = 1;
  for (int k = 1; k <= order; ++k)
    for (int i = k; i >= 0; --i)
      c[static_cast<size_t>(i)] = (i > 0 ? c[static_cast<size_t>(i) - 1] : 0.0)
          - (i < k ? c[static_cast<size_t>(i)] : 0.0);
  return c;
}

double median_of(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

constexpr int kSmoothingOrder = 3; ///< the Whittaker penalty's difference order (jerk)

/// DᵀD of the (T − order) × T difference operator of `order`.
Eigen::SparseMatrix<double> difference_gram(Eigen::Index frames, int order) {
  const auto stencil = difference_stencil(order);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index row = 0; row + order < frames; ++row)
    for (int a = 0; a <= order; ++a)
      for (int b = 0; b <= order; ++b)
        entries.emplace_back(
            row + a, row + b, stencil[static_cast<size_t>(a)] * stencil[static_cast<size_t>(b)]);
  Eigen::SparseMatrix<double> gram(frames, frames);
  gram.setFromTriplets(entries.begin(), entries.end());
  return gram;
}

} // namespace

double estimate_noise(const Observation& observed) {
  const MatX x = coordinate_series(observed);
  double best = std::numeric_limits<double>::infinity();
  for (int order : { 2, 3, 4 }) {
    if (x.rows() <= order + 1)
      return 0;
    const auto stencil = difference_stencil(order);
    std::vector<double> magnitudes;
    magnitudes.reserve(static_cast<size_t>((x.rows() - order) * x.cols()));
    for (Eigen::Index t = 0; t + order < x.rows(); ++t)
      for (Eigen::Index c = 0; c < x.cols(); ++c) {
        double d = 0;
        for (int i = 0; i <= order; ++i)
          d += stencil[static_cast<size_t>(i)] * x(t + i, c);
        magnitudes.push_back(std::abs(d));
      }
    double gain = 0; // Σ stencil² = C(2k, k)
    for (double s : stencil)
      gain += s * s;
    best = std::min(best, 1.4826 * median_of(magnitudes) / std::sqrt(gain));
  }
  return best;
}

SmoothingResult smooth_to_noise(const Observation& observed, double sigma) {
  if (!std::isfinite(sigma) || sigma < 0)
    throw InputError("noise", "must be a finite σ ≥ 0 [m], got " + std::to_string(sigma));
  SmoothingResult result;
  result.smoothed = observed;
  const MatX x = coordinate_series(observed);
  if (sigma == 0 || x.rows() <= kSmoothingOrder + 1 || x.size() == 0)
    return result;
  const Eigen::SparseMatrix<double> gram = difference_gram(x.rows(), kSmoothingOrder);
  Eigen::SparseMatrix<double> identity(x.rows(), x.rows());
  identity.setIdentity();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool analysed = false;
  // The change y − x = −κ (I + κDᵀD)⁻¹ DᵀD x is solved for, not y itself: DᵀD x is small for
  // smooth data (zero for constant acceleration), so the change keeps its precision at the large
  // κ where I + κDᵀD is ill-conditioned.
  const MatX jerk = gram * x;
  MatX change;
  const auto smooth = [&](double kappa) {
    const Eigen::SparseMatrix<double> a = identity + kappa * gram;
    if (!analysed) {
      solver.analyzePattern(a); // the pattern does not depend on κ
      analysed = true;
    }
    solver.factorize(a);
    change = -kappa * solver.solve(jerk);
    return std::sqrt(change.squaredNorm() / static_cast<double>(x.size()));
  };
  // The RMS change grows monotonically with κ (towards the least-squares quadratic in time);
  // bisect log κ for the discrepancy RMS change = σ, or take the largest κ if even that changes
  // the data by less.
  // κ ≤ 10⁸ keeps I + κDᵀD's condition number (≤ 1 + 64κ) where the solve is accurate; it
  // smooths every mode of period below ~2π(10⁸)^(1/6) ≈ 135 frames, which is noise or
  // already smooth motion.
  double lo = -8, hi = 8; // log₁₀ κ
  if (smooth(std::pow(10.0, hi)) <= sigma) {
    lo = hi;
  } else {
    for (int i = 0; i < 50 && hi - lo > 1e-3; ++i) {
      const double mid = 0.5 * (lo + hi);
      (smooth(std::pow(10.0, mid)) < sigma ? lo : hi) = mid;
    }
  }
  result.kappa = std::pow(10.0, lo);
  result.rms_change = smooth(result.kappa);
  for (Eigen::Index t = 0; t < change.rows(); ++t)
    for (int j = 0; j < observed.num_observed(); ++j)
      result.smoothed.positions[static_cast<size_t>(t)].row(j) += change.block<1, 3>(t, 3 * j);
  return result;
}

} // namespace elastolearn::observe
