#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/stability_cuts.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace elastolearn::learn {

namespace {

/// Stretches closer than this (relative) use the twist eigenvalue's limit, as
/// material::principal_tangent does.
constexpr double kTwistGap = 1e-5;
constexpr int kPairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };

bool twist_limit(const Vec3& s, int i, int j) {
  return std::abs(s[i] - s[j]) <= kTwistGap * std::max({ 1.0, std::abs(s[i]), std::abs(s[j]) });
}

/// The twist eigenvalue of principal stress `p` with stretch derivative `dp` for the pair (i, j).
double twist(const Vec3& s, const Vec3& p, const Mat3& dp, int i, int j) {
  return twist_limit(s, i, j) ? 0.5 * ((dp(i, i) - dp(i, j)) + (dp(j, j) - dp(j, i)))
                              : (p[i] - p[j]) / (s[i] - s[j]);
}

/// The cuts at one unstable sample (see stability_cuts), appended to `rows` and `bounds`.
void sample_cuts(const RbfDesign& design, const material::ElasticModel& nominal,
    const material::Correction& correction, const Vec3& s, double kept, std::vector<VecX>& rows,
    std::vector<double>& bounds) {
  const int elastic = design.elastic_unknowns();
  RbfDesign::OutputMatrix a(3, elastic);
  RbfDesign::OutputGradient gradient(9, elastic);
  design.output_matrix(s, a, gradient);
  const Vec3 p0 = nominal.principal_stress(s);
  const Mat3 dp0 = nominal.principal_stress_derivative(s);
  const material::CorrectedStress c
      = material::corrected_principal_stress(nominal, &correction, s, Vec3::Zero());
  const auto push = [&](const Eigen::RowVectorXd& row, double bound) {
    const double norm = row.norm();
    if (!(norm > 0))
      return; // the unknowns cannot change this stiffness
    VecX full = VecX::Zero(design.num_unknowns());
    full.head(elastic) = row.transpose() / norm;
    rows.push_back(std::move(full));
    bounds.push_back(bound / norm);
  };
  // ∂N_k/∂σ_j of the unknowns: gradient row 3j + k.
  const auto d_row = [&](int k, int j) { return gradient.row(3 * j + k); };
  const Mat3 block = 0.5 * (c.d_stretches + c.d_stretches.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(block);
  if (eigen.eigenvalues()[0] < 0) {
    const Vec3 d = eigen.eigenvectors().col(0);
    Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(elastic);
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        row += d[j] * d[k] * d_row(k, j);
    push(row, (kept - 1) * d.dot(dp0 * d));
  }
  for (const auto& pair : kPairs) {
    const int i = pair[0], j = pair[1];
    if (twist(s, c.stress, c.d_stretches, i, j) >= 0)
      continue;
    const Eigen::RowVectorXd row = twist_limit(s, i, j)
        ? Eigen::RowVectorXd(0.5 * ((d_row(i, i) - d_row(i, j)) + (d_row(j, j) - d_row(j, i))))
        : Eigen::RowVectorXd((a.row(i) - a.row(j)) / (s[i] - s[j]));
    const double nominal_twist = std::max(twist(s, p0, dp0, i, j), 0.0);
    push(row, kept * nominal_twist - twist(s, p0, dp0, i, j));
  }
}

} // namespace

void LinearInequalities::append(const LinearInequalities& more) {
  if (more.size() == 0)
    return;
  if (size() == 0) {
    *this = more;
    return;
  }
  ELASTOLEARN_CHECK(more.rows.cols() == rows.cols(), "LinearInequalities: unknowns differ");
  MatX joined(rows.rows() + more.rows.rows(), rows.cols());
  joined << rows, more.rows;
  VecX joined_bounds(bounds.size() + more.bounds.size());
  joined_bounds << bounds, more.bounds;
  rows = std::move(joined);
  bounds = std::move(joined_bounds);
}

LinearInequalities stability_cuts(const RbfDesign& design, const material::ElasticModel& nominal,
    ConstRef<VecX> x, ConstRef<MatX> samples, double kept, Eigen::Index max_cuts) {
  const material::RbfCorrection correction = design.correction(x);
  std::vector<double> stability(static_cast<size_t>(samples.rows()));
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, samples.rows(), 256),
      [&](const tbb::blocked_range<Eigen::Index>& range) {
        for (Eigen::Index i = range.begin(); i < range.end(); ++i)
          stability[static_cast<size_t>(i)]
              = relative_stability(nominal, &correction, samples.row(i).transpose());
      });
  std::vector<Eigen::Index> unstable;
  for (Eigen::Index i = 0; i < samples.rows(); ++i)
    if (stability[static_cast<size_t>(i)] < 0)
      unstable.push_back(i);
  std::sort(unstable.begin(), unstable.end(), [&](Eigen::Index a, Eigen::Index b) {
    return stability[static_cast<size_t>(a)] < stability[static_cast<size_t>(b)];
  });
  if (static_cast<Eigen::Index>(unstable.size()) > max_cuts)
    unstable.resize(static_cast<size_t>(max_cuts));
  std::vector<VecX> rows;
  std::vector<double> bounds;
  for (const Eigen::Index i : unstable)
    sample_cuts(design, nominal, correction, samples.row(i).transpose(), kept, rows, bounds);
  LinearInequalities out;
  out.rows.resize(static_cast<Eigen::Index>(rows.size()), design.num_unknowns());
  out.bounds.resize(static_cast<Eigen::Index>(rows.size()));
  for (size_t r = 0; r < rows.size(); ++r) {
    out.rows.row(static_cast<Eigen::Index>(r)) = rows[r].transpose();
    out.bounds[static_cast<Eigen::Index>(r)] = bounds[r];
  }
  return out;
}

VecX solve_with_inequalities(const RegularisedNormalEquations& equations, ConstRef<VecX> rhs,
    const LinearInequalities& conditions) {
  VecX x = equations.solve(rhs);
  const Eigen::Index k = conditions.size();
  if (k == 0 || (conditions.rows * x - conditions.bounds).minCoeff() >= 0)
    return x;
  const MatX y = equations.solve(conditions.rows.transpose()); // Q⁻¹Gᵀ
  const MatX m = conditions.rows * y;
  const VecX c = conditions.bounds - conditions.rows * x;
  VecX lambda = VecX::Zero(k);
  VecX w = -c; // Mλ − c
  const double tolerance = 1e-9 * c.norm();
  for (int sweep = 0; sweep < 2000; ++sweep) {
    for (Eigen::Index i = 0; i < k; ++i) {
      if (!(m(i, i) > 0))
        continue;
      const double next = std::max(0.0, lambda[i] - w[i] / m(i, i));
      if (next != lambda[i]) {
        w += m.col(i) * (next - lambda[i]);
        lambda[i] = next;
      }
    }
    double violation = 0;
    for (Eigen::Index i = 0; i < k; ++i)
      violation = std::max(violation, lambda[i] > 0 ? std::abs(w[i]) : -w[i]);
    if (violation <= tolerance)
      break;
  }
  x.noalias() += y * lambda;
  return x;
}

StableSolve stable_least_squares(const RegularisedNormalEquations& equations, ConstRef<VecX> rhs,
    const RbfDesign& design, const material::ElasticModel& nominal, ConstRef<MatX> samples,
    ConstRef<VecX> base, int max_rounds, const LinearInequalities& kept) {
  StableSolve out;
  LinearInequalities conditions = kept;
  out.x = solve_with_inequalities(equations, rhs, conditions);
  for (int round = 0; round < max_rounds; ++round) {
    LinearInequalities cuts = stability_cuts(design, nominal, base + out.x, samples);
    if (cuts.size() == 0)
      break;
    cuts.bounds -= cuts.rows * base; // G(base + x) ≥ h
    conditions.append(cuts);
    out.x = solve_with_inequalities(equations, rhs, conditions);
    out.rounds = round + 1;
  }
  out.cuts = conditions.size() - kept.size();
  return out;
}

} // namespace elastolearn::learn
