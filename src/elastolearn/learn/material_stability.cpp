#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace elastolearn::learn {

namespace {

/// The smallest eigenvalue of the stretch block's symmetric part and of the twist eigenvalues.
double smallest_eigenvalue(const material::PrincipalTangent& t) {
  const Mat3 block = 0.5 * (t.block + t.block.transpose());
  const double block_min
      = Eigen::SelfAdjointEigenSolver<Mat3>(block, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
  return std::min(block_min, t.twist.minCoeff());
}

/// A principal frame with the given stretches (U = V = I): the tangent's eigen-form depends on
/// the stretches only.
material::PrincipalFrame frame_of(const Vec3& stretches) {
  return { Mat3::Identity(), stretches, Mat3::Identity() };
}

} // namespace

double relative_stability(const material::ElasticModel& nominal,
    const material::Correction* correction, const Vec3& stretches) {
  const material::PrincipalFrame frame = frame_of(stretches);
  const double reference
      = std::max(smallest_eigenvalue(material::principal_tangent(nominal, frame, false)),
          std::numeric_limits<double>::min());
  const material::CorrectedStress c
      = material::corrected_principal_stress(nominal, correction, stretches, Vec3::Zero());
  return smallest_eigenvalue(material::principal_tangent(frame, c.stress, c.d_stretches, false))
      / reference;
}

StabilityReport material_stability(const material::ElasticModel& nominal,
    const material::Correction* correction, ConstRef<MatX> stretches) {
  struct Partial {
    double worst = std::numeric_limits<double>::infinity();
    Vec3 at = Vec3::Ones();
    long unstable = 0;
  };
  const Partial total = tbb::parallel_reduce(
      tbb::blocked_range<Eigen::Index>(0, stretches.rows(), 256), Partial {},
      [&](const tbb::blocked_range<Eigen::Index>& range, Partial p) {
        for (Eigen::Index i = range.begin(); i < range.end(); ++i) {
          const Vec3 s = stretches.row(i).transpose();
          const double relative = relative_stability(nominal, correction, s);
          if (relative < 0)
            ++p.unstable;
          if (relative < p.worst) {
            p.worst = relative;
            p.at = s;
          }
        }
        return p;
      },
      [](Partial a, const Partial& b) {
        a.unstable += b.unstable;
        if (b.worst < a.worst) {
          a.worst = b.worst;
          a.at = b.at;
        }
        return a;
      });
  StabilityReport r;
  r.samples = stretches.rows();
  r.unstable_samples = total.unstable;
  r.min_relative_eigenvalue = r.samples > 0 ? total.worst : 0;
  r.worst_stretches = total.at;
  return r;
}

std::string describe_unstable(const StabilityReport& report, const std::string& what) {
  const Vec3& s = report.worst_stretches;
  char numbers[160];
  std::snprintf(numbers, sizeof numbers,
      " (stiffness %.3g × the nominal's at σ = (%.4f, %.4f, %.4f))", report.min_relative_eigenvalue,
      s(0), s(1), s(2));
  return "unstable at " + std::to_string(report.unstable_samples) + " of "
      + std::to_string(report.samples) + " " + what + numbers;
}

MatX amplified_stretches(
    ConstRef<MatX> stretches, std::span<const double> amplifications, Eigen::Index max_rows) {
  const auto powers = static_cast<Eigen::Index>(amplifications.size());
  const Eigen::Index step = std::max<Eigen::Index>(
      1, (powers * stretches.rows() + max_rows - 1) / std::max<Eigen::Index>(max_rows, 1));
  const Eigen::Index kept = (stretches.rows() + step - 1) / step;
  MatX out(powers * kept, 3);
  Eigen::Index row = 0;
  for (const double a : amplifications)
    for (Eigen::Index i = 0; i < stretches.rows(); i += step, ++row)
      for (int c = 0; c < 3; ++c)
        out(row, c) = stretches(i, c) > 0 ? std::pow(stretches(i, c), a) : stretches(i, c);
  return out;
}

MatX reachable_stretches(const material::ElasticModel& nominal, ConstRef<MatX> stretches,
    double amplification, double stress_factor, double spacing) {
  ELASTOLEARN_CHECK(spacing > 0 && amplification >= 1 && stress_factor > 0,
      "reachable_stretches: needs spacing > 0, amplification ≥ 1, stress_factor > 0");
  // Over the uninverted samples (σ₃ > 0): an inverted element says nothing about the stresses
  // of the motion, and log-amplifying it is undefined.
  double low = std::numeric_limits<double>::infinity(), high = 0, largest_stress = 0;
  double j_low = std::numeric_limits<double>::infinity(), j_high = 0;
  for (Eigen::Index i = 0; i < stretches.rows(); ++i) {
    const Vec3 s = stretches.row(i).transpose();
    if (!(s.minCoeff() > 0))
      continue;
    low = std::min(low, s.minCoeff());
    high = std::max(high, s.maxCoeff());
    j_low = std::min(j_low, s.prod());
    j_high = std::max(j_high, s.prod());
    largest_stress = std::max(largest_stress, nominal.principal_stress(s).norm());
  }
  if (!(high > 0))
    return MatX(0, 3);
  low = std::pow(low, amplification);
  high = std::pow(high, amplification);
  const double bound = stress_factor * largest_stress;
  const int n = std::clamp(static_cast<int>(std::ceil((high - low) / spacing)) + 1,
      kReachableMinPoints, kReachableMaxPoints);
  const double step = (high - low) / (n - 1);
  const auto at = [&](int k) { return low + step * k; };
  // Volume changes as far as the data's, amplified alike, and one grid step wider (a grid point
  // changes J by about a step: an isochoric data set keeps a shell of samples around J = 1).
  j_low = std::min(std::pow(j_low, amplification), j_low) - step;
  j_high = std::max(std::pow(j_high, amplification), j_high) + step;
  std::vector<Vec3> kept;
  for (int i = 0; i < n; ++i) // σ₁ ≥ σ₂ ≥ σ₃: i ≥ j ≥ k
    for (int j = 0; j <= i; ++j)
      for (int k = 0; k <= j; ++k) {
        const Vec3 s(at(i), at(j), at(k));
        const double volume = s.prod();
        if (volume >= j_low && volume <= j_high && nominal.principal_stress(s).norm() <= bound)
          kept.push_back(s);
      }
  MatX out(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t r = 0; r < kept.size(); ++r)
    out.row(static_cast<Eigen::Index>(r)) = kept[r].transpose();
  return out;
}

} // namespace elastolearn::learn
