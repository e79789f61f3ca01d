#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/observation_noise.hpp>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
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

/// Frame t of point j was seen, for each t: column j of the mask (all ones without a mask).
std::vector<std::uint8_t> seen_frames(const Observation& observed, int j) {
  std::vector<std::uint8_t> seen(static_cast<size_t>(observed.num_frames()), 1);
  if (observed.valid.size() != 0)
    for (int t = 0; t < observed.num_frames(); ++t)
      seen[static_cast<size_t>(t)] = observed.valid(t, j) != 0 ? 1 : 0;
  return seen;
}

/// The points that share one mask column, and that column.
struct MaskGroup {
  std::vector<std::uint8_t> seen; ///< per frame
  std::vector<int> points;
  long num_seen = 0;
};

/// The observed points grouped by their mask column, in order of first appearance (one group
/// of every point without a mask). Points never seen are in no group.
std::vector<MaskGroup> mask_groups(const Observation& observed) {
  std::vector<MaskGroup> groups;
  std::map<std::string, size_t> index; // a mask column's bytes → its group
  for (int j = 0; j < observed.num_observed(); ++j) {
    std::vector<std::uint8_t> seen = seen_frames(observed, j);
    const long count = std::count(seen.begin(), seen.end(), std::uint8_t(1));
    if (count == 0)
      continue;
    const auto [it, added]
        = index.try_emplace(std::string(seen.begin(), seen.end()), groups.size());
    if (added)
      groups.push_back({ std::move(seen), {}, count });
    groups[it->second].points.push_back(j);
  }
  return groups;
}

/// Frames × (3 · points) matrix of the given points' coordinates, in their order.
MatX point_columns(const MatX& x, const std::vector<int>& points) {
  MatX out(x.rows(), 3 * static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i)
    out.middleCols<3>(3 * static_cast<Eigen::Index>(i)) = x.middleCols<3>(3 * points[i]);
  return out;
}

/// x with the lost rows of the group's points replaced by the minimiser of ‖Δ^q y‖² over them
/// (the seen rows fixed), q = min(3, seen frames): the lost rows solve G_LL y_L = −G_LS x_S with
/// G = DᵀD, positive definite since no nonzero polynomial of degree < q vanishes on q frames.
void fill_group(MatX& x, const MaskGroup& group) {
  const auto frames = x.rows();
  if (group.num_seen == frames)
    return;
  const int order = static_cast<int>(std::min<long>(kSmoothingOrder, group.num_seen));
  const Eigen::SparseMatrix<double> gram = difference_gram(frames, order);
  std::vector<Eigen::Index> lost_index(static_cast<size_t>(frames), -1);
  std::vector<Eigen::Index> lost;
  for (Eigen::Index t = 0; t < frames; ++t)
    if (!group.seen[static_cast<size_t>(t)]) {
      lost_index[static_cast<size_t>(t)] = static_cast<Eigen::Index>(lost.size());
      lost.push_back(t);
    }
  const auto m = static_cast<Eigen::Index>(lost.size());
  const auto columns = 3 * static_cast<Eigen::Index>(group.points.size());
  std::vector<Eigen::Triplet<double>> entries;
  MatX rhs = MatX::Zero(m, columns);
  for (Eigen::Index col = 0; col < gram.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(gram, col); it; ++it) {
      const Eigen::Index row = lost_index[static_cast<size_t>(it.row())];
      if (row < 0)
        continue;
      const Eigen::Index other = lost_index[static_cast<size_t>(col)];
      if (other >= 0) {
        entries.emplace_back(row, other, it.value());
      } else {
        for (size_t i = 0; i < group.points.size(); ++i)
          rhs.row(row).segment<3>(3 * static_cast<Eigen::Index>(i))
              -= it.value() * x.block<1, 3>(col, 3 * group.points[i]);
      }
    }
  Eigen::SparseMatrix<double> lost_gram(m, m);
  lost_gram.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(lost_gram);
  ELASTOLEARN_CHECK(solver.info() == Eigen::Success, "the gap fill's matrix is positive definite");
  const MatX filled = solver.solve(rhs);
  for (Eigen::Index r = 0; r < m; ++r)
    for (size_t i = 0; i < group.points.size(); ++i)
      x.block<1, 3>(lost[static_cast<size_t>(r)], 3 * group.points[i])
          = filled.row(r).segment<3>(3 * static_cast<Eigen::Index>(i));
}

/// Write the coordinate series x back into the positions of `observed`'s grouped points.
void store_columns(const MatX& x, const std::vector<MaskGroup>& groups, Observation& observed) {
  for (const MaskGroup& group : groups)
    for (const int j : group.points)
      for (Eigen::Index t = 0; t < x.rows(); ++t)
        observed.positions[static_cast<size_t>(t)].row(j) = x.block<1, 3>(t, 3 * j);
}

} // namespace

double estimate_noise(const Observation& observed) {
  const MatX x = coordinate_series(observed);
  double best = std::numeric_limits<double>::infinity();
  std::vector<std::vector<std::uint8_t>> seen;
  seen.reserve(static_cast<size_t>(observed.num_observed()));
  for (int j = 0; j < observed.num_observed(); ++j)
    seen.push_back(seen_frames(observed, j));
  for (int order : { 2, 3, 4 }) {
    if (x.rows() <= order + 1)
      return 0;
    const auto stencil = difference_stencil(order);
    std::vector<double> magnitudes;
    magnitudes.reserve(static_cast<size_t>((x.rows() - order) * x.cols()));
    for (Eigen::Index t = 0; t + order < x.rows(); ++t)
      for (Eigen::Index c = 0; c < x.cols(); ++c) {
        // Only differences over frames that were all seen: a lost position means nothing.
        const auto& point_seen = seen[static_cast<size_t>(c / 3)];
        if (!std::all_of(point_seen.begin() + t, point_seen.begin() + t + order + 1,
                [](std::uint8_t s) { return s != 0; }))
          continue;
        double d = 0;
        for (int i = 0; i <= order; ++i)
          d += stencil[static_cast<size_t>(i)] * x(t + i, c);
        magnitudes.push_back(std::abs(d));
      }
    if (magnitudes.empty())
      continue; // no point seen in order + 1 consecutive frames
    double gain = 0; // Σ stencil² = C(2k, k)
    for (double s : stencil)
      gain += s * s;
    best = std::min(best, 1.4826 * median_of(magnitudes) / std::sqrt(gain));
  }
  return std::isfinite(best) ? best : 0;
}

Observation fill_lost_entries(const Observation& observed) {
  Observation out = observed;
  if (!observed.has_lost_entries())
    return out;
  MatX x = coordinate_series(observed);
  const std::vector<MaskGroup> groups = mask_groups(observed);
  for (const MaskGroup& group : groups)
    fill_group(x, group);
  store_columns(x, groups, out);
  return out;
}

SmoothingResult smooth_to_noise(const Observation& observed, double sigma) {
  if (!std::isfinite(sigma) || sigma < 0)
    throw InputError("noise", "must be a finite σ ≥ 0 [m], got " + std::to_string(sigma));
  SmoothingResult result;
  result.smoothed = fill_lost_entries(observed);
  if (sigma == 0 || observed.num_frames() <= kSmoothingOrder + 1 || observed.num_observed() == 0)
    return result;
  // The fill is the starting series: it depends only on the seen entries, and the change below
  // solves with W = diag(seen), so y = x + change does not depend on it either.
  const MatX x = coordinate_series(result.smoothed);
  const auto frames = x.rows();
  // Points seen in fewer frames than the penalty's order: W + κDᵀD is singular, so they stay
  // as filled.
  std::vector<MaskGroup> groups = mask_groups(observed);
  std::erase_if(groups, [](const MaskGroup& g) { return g.num_seen < kSmoothingOrder; });
  if (groups.empty())
    return result;
  long seen_coordinates = 0;
  for (const MaskGroup& g : groups)
    seen_coordinates += 3 * g.num_seen * static_cast<long>(g.points.size());
  const Eigen::SparseMatrix<double> gram = difference_gram(frames, kSmoothingOrder);
  struct GroupSystem {
    Eigen::SparseMatrix<double> weight; ///< W = diag(seen)
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
    MatX jerk; ///< DᵀD x of the group's coordinates
    MatX change;
    bool analysed = false;
  };
  std::vector<GroupSystem> systems(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) {
    systems[g].weight.resize(frames, frames);
    std::vector<Eigen::Triplet<double>> diagonal;
    for (Eigen::Index t = 0; t < frames; ++t)
      if (groups[g].seen[static_cast<size_t>(t)])
        diagonal.emplace_back(t, t, 1.0);
    systems[g].weight.setFromTriplets(diagonal.begin(), diagonal.end());
    // One group of every point (no lost entry): its columns in order, as x itself.
    systems[g].jerk = groups.size() == 1 && groups[g].num_seen == frames
            && static_cast<int>(groups[g].points.size()) == observed.num_observed()
        ? MatX(gram * x)
        : MatX(gram * point_columns(x, groups[g].points));
  }
  // The change y − x = −κ (W + κDᵀD)⁻¹ DᵀD x is solved for, not y itself: DᵀD x is small for
  // smooth data (zero for constant acceleration), so the change keeps its precision at the large
  // κ where W + κDᵀD is ill-conditioned. (With W = I the smoother of every point seen in every
  // frame; lost rows of W are 0, so the data term sees only seen entries.)
  const auto smooth = [&](double kappa) {
    double squares = 0;
    for (size_t g = 0; g < groups.size(); ++g) {
      GroupSystem& s = systems[g];
      const Eigen::SparseMatrix<double> a = s.weight + kappa * gram;
      if (!s.analysed) {
        s.solver.analyzePattern(a); // the pattern does not depend on κ
        s.analysed = true;
      }
      s.solver.factorize(a);
      s.change = -kappa * s.solver.solve(s.jerk);
      if (groups[g].num_seen == frames) {
        squares += s.change.squaredNorm();
      } else {
        for (Eigen::Index t = 0; t < frames; ++t)
          if (groups[g].seen[static_cast<size_t>(t)])
            squares += s.change.row(t).squaredNorm();
      }
    }
    return std::sqrt(squares / static_cast<double>(seen_coordinates));
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
  for (size_t g = 0; g < groups.size(); ++g)
    for (size_t i = 0; i < groups[g].points.size(); ++i) {
      const int j = groups[g].points[i];
      for (Eigen::Index t = 0; t < frames; ++t)
        result.smoothed.positions[static_cast<size_t>(t)].row(j)
            += systems[g].change.block<1, 3>(t, 3 * static_cast<Eigen::Index>(i));
    }
  return result;
}

} // namespace elastolearn::observe
