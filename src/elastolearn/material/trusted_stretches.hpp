#pragma once
/// \file A learned energy correction's trusted stretches: the interval of principal stretches it
/// was learned from. Beyond it the correction's energy ΔΨ is continued by a second-order expansion
/// at the nearest trusted point c = clamp(σ), N(σ) = N(c) + H(σ − c), instead of following
/// polynomial tails or kernels (RBF) or activations (network) where no data constrained them
/// (docs/learning_recipe.md, "Beyond the data"). H is the edge's Hessian ∇²ΔΨ(c), with
/// Continuation::bounded_softening (what learning writes) limited so that the nominal's rest
/// stiffness K₀ plus H keeps a fraction β of K₀ in every stretch direction: K₀ + H ⪰ β K₀. A
/// correction that removed part of the nominal's stiffness at the edge then removes no more
/// than 1 − β of it however far beyond, while one that keeps enough is continued as the data
/// made it. With the whole edge Hessian (edge_hessian, files written without a "continuation")
/// a correction softened at a corner of the interval no motion visited can remove more than all
/// the nominal's stiffness beyond it: random case 5 of seed 10 (a droop to s₃ 0.913, a swing to
/// 0.619) diverged that way. N is continuous and its tangent symmetric everywhere; where every
/// stretch is beyond the same end N is exactly the gradient of the continued energy, elsewhere
/// outside up to terms of second order in σ − c (the third derivatives the expansion leaves
/// out). Where the bound is active the tangent jumps at the edge.
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/types.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace elastolearn::material {

/// How ΔΨ is continued beyond the trusted stretches (the file's "continuation").
enum class Continuation {
  edge_hessian, ///< with the edge's Hessian ∇²ΔΨ(c) (files written before "continuation")
  bounded_softening, ///< with it bounded below: K₀ + H ⪰ β K₀
};

/// The fraction β of the nominal's rest stiffness a continued correction keeps (learning's).
inline constexpr double kKeptStiffness = 0.5;

struct TrustedStretches {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  Continuation continuation = Continuation::edge_hessian;
  /// bounded_softening: K₀, the nominal's ∂P̂/∂σ at rest (symmetric positive definite) [Pa], and
  /// β ∈ [0, 1].
  Mat3 nominal_stiffness = Mat3::Zero();
  double kept_stiffness = kKeptStiffness;

  bool bounded() const { return std::isfinite(min) || std::isfinite(max); }
  /// The nearest trusted point: σ clamped to [min, max] componentwise (σ itself inside).
  Vec3 nearest(const Vec3& stretches) const { return stretches.cwiseMax(min).cwiseMin(max); }
  /// The Hessian the continuation uses beyond the edge, from the edge's Hessian ∇²ΔΨ(c). With
  /// bounded_softening: in K₀'s metric, M = K₀^(−½) H K₀^(−½) with its eigenvalues raised to at
  /// least β − 1, mapped back. 3 × 3 symmetric: closed-form eigensolvers, no allocation. Any
  /// factor of K₀ is equal in exact arithmetic, but a learned result can depend on rounding, and
  /// the recipe's measured results (docs/benchmarks_learning.md) use this symmetric root.
  Mat3 continued_hessian(const Mat3& edge_hessian) const {
    if (continuation == Continuation::edge_hessian)
      return edge_hessian;
    Eigen::SelfAdjointEigenSolver<Mat3> k;
    k.computeDirect(nominal_stiffness);
    const Vec3 root = k.eigenvalues().cwiseSqrt();
    const Mat3 to_metric = k.eigenvectors() * root.cwiseInverse().asDiagonal()
        * k.eigenvectors().transpose(); // K₀^(−½)
    const Mat3 from_metric = k.eigenvectors() * root.asDiagonal() * k.eigenvectors().transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> m;
    m.computeDirect(to_metric * (0.5 * (edge_hessian + edge_hessian.transpose())) * to_metric);
    if (m.eigenvalues().minCoeff() >= kept_stiffness - 1)
      return edge_hessian;
    return from_metric
        * (m.eigenvectors() * m.eigenvalues().cwiseMax(kept_stiffness - 1).asDiagonal()
            * m.eigenvectors().transpose())
        * from_metric;
  }
  /// Throws InputError(`field`, ...) unless min ≤ max (neither NaN) and, for
  /// bounded_softening, K₀ is symmetric positive definite and 0 ≤ β ≤ 1.
  void validate(const std::string& field) const {
    if (std::isnan(min) || std::isnan(max) || !(min <= max))
      throw InputError(field, "must be an interval [min, max] with min ≤ max");
    if (continuation == Continuation::bounded_softening) {
      if (!nominal_stiffness.allFinite()
          || (nominal_stiffness - nominal_stiffness.transpose()).norm()
              > 1e-12 * nominal_stiffness.norm()
          || Eigen::LLT<Mat3>(nominal_stiffness).info() != Eigen::Success)
        throw InputError(field, "nominal_stiffness must be symmetric positive definite");
      if (!(kept_stiffness >= 0 && kept_stiffness <= 1))
        throw InputError(field, "kept_stiffness must be in [0, 1]");
    }
  }
};

/// N at σ, continued beyond `trusted`: `formula(c, hessian)` gives N at c and, if `hessian` is
/// non-null, ∇²ΔΨ(c) there. `tangent` (if non-null) receives ∂N/∂σ (outside: the continued
/// Hessian, TrustedStretches::continued_hessian).
template <typename Formula>
Vec3 continued_correction(
    const TrustedStretches& trusted, const Vec3& stretches, Mat3* tangent, const Formula& formula) {
  const Vec3 c = trusted.nearest(stretches);
  if (c == stretches)
    return formula(stretches, tangent);
  Mat3 edge;
  const Vec3 n = formula(c, &edge);
  const Mat3 hessian = trusted.continued_hessian(edge);
  if (tangent != nullptr)
    *tangent = hessian;
  return n + hessian * (stretches - c);
}

/// ΔΨ at σ, continued beyond `trusted` like continued_correction: `energy(c)` is ΔΨ at c,
/// `formula` as there.
template <typename Energy, typename Formula>
double continued_energy(const TrustedStretches& trusted, const Vec3& stretches,
    const Energy& energy, const Formula& formula) {
  const Vec3 c = trusted.nearest(stretches);
  if (c == stretches)
    return energy(stretches);
  Mat3 edge;
  const Vec3 n = formula(c, &edge), d = stretches - c;
  const Mat3 hessian = trusted.continued_hessian(edge);
  return energy(c) + n.dot(d) + 0.5 * d.dot(hessian * d);
}

} // namespace elastolearn::material
