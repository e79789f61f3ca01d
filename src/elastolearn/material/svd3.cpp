#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/svd3.hpp>

#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <utility>

namespace elastolearn::material {

namespace {

/// Two columns count as orthogonal when |cos| ≤ this. The computed dot product of two orthogonal
/// 3-vectors carries rounding up to 3ε ≈ 6.7e-16 relative, so 1e-15 is the smallest tolerance
/// the iteration can always meet; it makes U orthogonal to ~1e-15.
constexpr double kCosineTolerance = 1e-15;
constexpr double kCosineTolerance2 = kCosineTolerance * kCosineTolerance;

/// Squared column norms below this are treated as zero columns (never rotated, their direction
/// in U completed orthonormally). F is pre-scaled so its largest entry is ≥ 2⁻¹⁰⁰, so this is at
/// most ~1e-60 of ‖F‖²: the reconstruction error it allows is far below rounding, and products of
/// two squared norms stay clear of underflow.
constexpr double kTinySquaredNorm = 1e-120;

/// One-sided Jacobi converges quadratically; 3×3 inputs need 2–6 sweeps (the last one a check).
constexpr int kMaxSweeps = 12;

/// Below this |2γ / (β − α)| the rotation angle is small and its tangent and cosine come from
/// short series (one division, no square roots); above it the closed form is used.
constexpr double kSmallAngle = 1e-3;

/// Rotate columns p, q of B = F V (and of V) so that they become orthogonal. Returns false if
/// they already are (within tolerance) or one of them is negligible.
[[gnu::always_inline]] inline bool orthogonalise(Vec3& bp, Vec3& bq, Vec3& vp, Vec3& vq) {
  const double alpha = bp.squaredNorm();
  const double beta = bq.squaredNorm();
  const double gamma = bp.dot(bq);
  if (gamma * gamma <= kCosineTolerance2 * (alpha * beta) || alpha < kTinySquaredNorm
      || beta < kTinySquaredNorm)
    return false;
  // Rotation [c s; −s c] zeroing the off-diagonal of [α γ; γ β], the smaller angle (|θ| ≤ π/4):
  // tan θ = z / (1 + √(1 + z²)) with z = y / x, x = β − α, y = 2γ.
  const double x = beta - alpha;
  const double y = 2 * gamma;
  double c, s;
  if (std::abs(y) < kSmallAngle * std::abs(x)) {
    // tan θ = (z/2)(1 − z²/4 + z⁴/8 − …) and cos θ = (1 + t²)^(−1/2) = 1 − t²/2 + 3t⁴/8 − …;
    // the truncation (≤ 1e-19 relative for |z| < 1e-3) keeps c² + s² = 1 to rounding.
    const double z = y / x;
    const double z2 = z * z;
    const double t = 0.5 * z * (1 - 0.25 * z2 + 0.125 * z2 * z2);
    const double t2 = t * t;
    c = 1 - 0.5 * t2 + 0.375 * t2 * t2;
    s = c * t;
  } else {
    // Closed form without overflow: r = √(x² + y²), c = √((|x| + r) / 2r),
    // s = sign(x) y / √(2r(|x| + r)).
    const double r = std::sqrt(x * x + y * y);
    const double w = std::abs(x) + r;
    const double inv = 1.0 / std::sqrt(2 * r * w);
    c = w * inv;
    s = std::copysign(1.0, x) * y * inv;
  }
  const Vec3 b = bp;
  bp = c * b - s * bq;
  bq = s * b + c * bq;
  const Vec3 v = vp;
  vp = c * v - s * vq;
  vq = s * v + c * vq;
  return true;
}

/// Sort key swap that keeps B = F V and det V = +1: swap columns i, j and negate the new j-th.
inline void swap_columns(Vec3* b, Vec3* v, double* n, int i, int j) {
  std::swap(b[i], b[j]);
  std::swap(v[i], v[j]);
  std::swap(n[i], n[j]);
  b[j] = -b[j];
  v[j] = -v[j];
}

/// A unit vector orthogonal to the unit vector u.
inline Vec3 any_orthogonal(const Vec3& u) {
  Eigen::Index axis;
  u.cwiseAbs().minCoeff(&axis);
  return u.cross(Vec3::Unit(axis)).normalized();
}

/// The reference path: Eigen's two-sided JacobiSVD with the inversion-safe sign convention.
PrincipalFrame jacobi_svd(const Mat3& F) {
  const Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  PrincipalFrame frame { svd.matrixU(), svd.singularValues(), svd.matrixV() };
  if (frame.U.determinant() < 0) {
    frame.U.col(2) *= -1;
    frame.stretches[2] *= -1;
  }
  if (frame.V.determinant() < 0) {
    frame.V.col(2) *= -1;
    frame.stretches[2] *= -1;
  }
  return frame;
}

} // namespace

PrincipalFrame svd3(const Mat3& F, Svd3Info* info) {
  Svd3Info local;
  Svd3Info& stats = info != nullptr ? *info : local;
  stats = Svd3Info {};

  if (!F.allFinite()) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    return { Mat3::Constant(nan), Vec3::Constant(nan), Mat3::Constant(nan) };
  }
  const double m = F.cwiseAbs().maxCoeff();
  if (m == 0)
    return { Mat3::Identity(), Vec3::Zero(), Mat3::Identity() };
  // Power-of-two scaling (exact) for extreme magnitudes only.
  double scale = 1, unscale = 1;
  if (m < 0x1p-100 || m > 0x1p100) {
    const int e = std::ilogb(m);
    scale = std::ldexp(1.0, -e);
    unscale = std::ldexp(1.0, e);
  }

  Vec3 b[3] = { scale * F.col(0), scale * F.col(1), scale * F.col(2) };
  Vec3 v[3] = { Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ() };
  bool converged = false;
  while (stats.sweeps < kMaxSweeps) {
    ++stats.sweeps;
    int rotated = 0;
    rotated += orthogonalise(b[0], b[1], v[0], v[1]);
    rotated += orthogonalise(b[0], b[2], v[0], v[2]);
    rotated += orthogonalise(b[1], b[2], v[1], v[2]);
    stats.rotations += rotated;
    if (rotated == 0) {
      converged = true;
      break;
    }
  }
  if (!converged) {
    stats.fallback = true;
    return jacobi_svd(F);
  }

  // Sort by column norm, descending (singular values are the column norms).
  double n[3] = { b[0].squaredNorm(), b[1].squaredNorm(), b[2].squaredNorm() };
  if (n[0] < n[1])
    swap_columns(b, v, n, 0, 1);
  if (n[0] < n[2])
    swap_columns(b, v, n, 0, 2);
  if (n[1] < n[2])
    swap_columns(b, v, n, 1, 2);

  PrincipalFrame frame;
  const double s0 = std::sqrt(n[0]); // n[0] ≥ m² scale² > 0
  const Vec3 u0 = (1 / s0) * b[0];
  Vec3 u1;
  if (n[1] >= kTinySquaredNorm) {
    // b1 ⟂ b0 to 1e-15 already; one Gram–Schmidt step makes u1 ⟂ u0 to rounding.
    const Vec3 w = b[1] - u0.dot(b[1]) * u0;
    u1 = (1 / std::sqrt(w.squaredNorm())) * w;
  } else {
    u1 = any_orthogonal(u0);
  }
  const Vec3 u2 = u0.cross(u1); // det U = +1
  frame.U << u0, u1, u2;
  frame.V << v[0], v[1], v[2];
  // |σ₂| = ‖b₂‖ (so |σ₂| ≤ σ₁ exactly); its sign is that of det F (b₂ = ±‖b₂‖ u₂).
  frame.stretches = Vec3(s0, std::sqrt(n[1]), std::copysign(std::sqrt(n[2]), u2.dot(b[2])));
  frame.stretches *= unscale;
  return frame;
}

} // namespace elastolearn::material
