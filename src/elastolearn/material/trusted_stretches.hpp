#pragma once
/// \file A learned energy correction's trusted stretches: the interval of principal stretches it
/// was learned from. Beyond it the correction's energy ΔΨ is continued by its second-order Taylor
/// expansion at the nearest trusted point c = clamp(σ), N(σ) = N(c) + ∇²ΔΨ(c)(σ − c): the
/// stiffness stays what the data made it at the edge instead of following polynomial tails or
/// kernels (RBF) or activations (network) where no data constrained them
/// (docs/learning_recipe.md, "Beyond the data"). N is continuous and its tangent symmetric
/// everywhere; where every stretch is beyond the same end N is exactly the gradient of the
/// continued energy, elsewhere outside up to terms of second order in σ − c (the third
/// derivatives the expansion leaves out).
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/types.hpp>

#include <cmath>
#include <limits>

namespace elastolearn::material {

struct TrustedStretches {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();

  bool bounded() const { return std::isfinite(min) || std::isfinite(max); }
  /// The nearest trusted point: σ clamped to [min, max] componentwise (σ itself inside).
  Vec3 nearest(const Vec3& stretches) const { return stretches.cwiseMax(min).cwiseMin(max); }
  /// Throws InputError(`field`, ...) unless min ≤ max (neither NaN).
  void validate(const std::string& field) const {
    if (std::isnan(min) || std::isnan(max) || !(min <= max))
      throw InputError(field, "must be an interval [min, max] with min ≤ max");
  }
};

/// N at σ, continued beyond `trusted`: `formula(c, hessian)` gives N at c and, if `hessian` is
/// non-null, ∇²ΔΨ(c) there. `tangent` (if non-null) receives ∂N/∂σ (the edge's Hessian outside).
template <typename Formula>
Vec3 continued_correction(
    const TrustedStretches& trusted, const Vec3& stretches, Mat3* tangent, const Formula& formula) {
  const Vec3 c = trusted.nearest(stretches);
  if (c == stretches)
    return formula(stretches, tangent);
  Mat3 hessian;
  const Vec3 n = formula(c, &hessian);
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
  Mat3 hessian;
  const Vec3 n = formula(c, &hessian), d = stretches - c;
  return energy(c) + n.dot(d) + 0.5 * d.dot(hessian * d);
}

} // namespace elastolearn::material
