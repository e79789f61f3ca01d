#pragma once
/// \file A learned energy correction's trusted stretches: the interval of principal stretches it
/// was learned from, and how its energy ΔΨ is continued beyond it instead of following
/// polynomial tails or kernels (RBF) or activations (network) where no data constrained them
/// (docs/learning_recipe.md, "Beyond the data").
///
/// Continuation::bounded_softening (what learning writes by default) continues ΔΨ by a
/// second-order expansion at the nearest trusted point c = clamp(σ), N(σ) = N(c) + H(σ − c), H the
/// edge's Hessian ∇²ΔΨ(c) bounded below by the nominal's rest stiffness K₀: K₀ + H ⪰ β K₀, so a
/// correction that removed part of the nominal's stiffness at the edge removes no more than
/// 1 − β of it however far beyond (with the whole edge Hessian, edge_hessian, files written
/// without a "continuation", random case 5 of seed 10 diverged that way).
///
/// Continuation::smooth_clamp (`learn --continuation smooth_clamp`) evaluates ΔΨ at φ(σ), each
/// stretch mapped through a C² function that is the identity inside and saturates within w
/// beyond an end, and continues each end's uniaxial stress and stiffness along a stretch beyond
/// it: ΔΨ(φ(σ)) + Σᵢ [gᵢ dᵢ + ½ kᵢ dᵢ²], dᵢ = σᵢ − φ(σᵢ). It is an energy everywhere, its tangent
/// is the exact derivative of its stress, and far beyond an end the other stretches see the
/// correction as it is within w/2 of the edge.
///
/// The expansions are exact energies where every stretch is beyond the same end. Where some
/// stretches are beyond an end and others inside, c moves with the inside ones, and ∂N/∂σ then
/// holds third derivatives of ΔΨ times the distance beyond the end that the tangent H leaves
/// out: Newton's matrix and the stability check see a stiffness the stress field does not have
/// (seed 12's case 12 of the random benchmark stalled that way; the smooth clamp completes it).
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/types.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastolearn::material {

/// How ΔΨ is continued beyond the trusted stretches (the file's "continuation").
enum class Continuation {
  edge_hessian, ///< with the edge's Hessian ∇²ΔΨ(c) (files written before "continuation")
  bounded_softening, ///< with it bounded below: K₀ + H ⪰ β K₀
  smooth_clamp, ///< ΔΨ(φ(σ)) + each end's uniaxial stress and stiffness beyond it (exact)
};

/// The continuation's name in files and options ("edge_hessian", "bounded_softening",
/// "smooth_clamp").
inline const char* continuation_name(Continuation c) {
  switch (c) {
  case Continuation::edge_hessian:
    return "edge_hessian";
  case Continuation::bounded_softening:
    return "bounded_softening";
  case Continuation::smooth_clamp:
    return "smooth_clamp";
  }
  return "edge_hessian";
}

/// The continuation named `name`; throws InputError(`field`, ...) naming the choices otherwise.
inline Continuation continuation_from_name(const std::string& name, const std::string& field) {
  for (const Continuation c :
      { Continuation::edge_hessian, Continuation::bounded_softening, Continuation::smooth_clamp })
    if (name == continuation_name(c))
      return c;
  throw InputError(field,
      "unknown continuation \"" + name
          + "\" (expected edge_hessian, bounded_softening or smooth_clamp)");
}

/// The fraction β of the nominal's rest stiffness a continued correction keeps (learning's).
inline constexpr double kKeptStiffness = 0.5;

/// smooth_clamp's transition width w (stretch units, learning's): the formula's stiffness along a
/// stretch beyond an end gives way to the end's between the end and w beyond it. Wider than the
/// energy kernels' smoothing ε = 0.03, as the transition adds up to 1.5/w times the variation of
/// the correction's stress there.
inline constexpr double kClampWidth = 0.1;

/// One stretch through smooth_clamp's map φ, with φ' and φ''.
struct ClampedStretch {
  double value = 0, slope = 1, curvature = 0;
};

struct TrustedStretches {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  Continuation continuation = Continuation::edge_hessian;
  /// bounded_softening and smooth_clamp: K₀, the nominal's ∂P̂/∂σ at rest (symmetric positive
  /// definite) [Pa], and β ∈ [0, 1].
  Mat3 nominal_stiffness = Mat3::Zero();
  double kept_stiffness = kKeptStiffness;
  /// smooth_clamp: the transition width w [-] (> 0).
  double clamp_width = kClampWidth;

  bool bounded() const { return std::isfinite(min) || std::isfinite(max); }
  /// The nearest trusted point: σ clamped to [min, max] componentwise (σ itself inside).
  Vec3 nearest(const Vec3& stretches) const { return stretches.cwiseMax(min).cwiseMin(max); }
  /// smooth_clamp's φ of one stretch: the identity inside [min, max]; at a distance t beyond an
  /// end, end ± w q(t/w) with q(x) = x − x³ + x⁴/2 for x ≤ 1 and ½ after, so φ' = 1 − 3x² + 2x³
  /// falls from 1 to 0 and φ'' = ∓6x(1 − x)/w is zero at both x = 0 and x = 1: φ is C² and
  /// bounded, never leaving [min − w/2, max + w/2].
  ClampedStretch smooth_clamp(double s) const {
    const double t = s > max ? s - max : s < min ? min - s : 0;
    if (t == 0)
      return { s, 1, 0 };
    const double sign = s > max ? 1 : -1, end = s > max ? max : min, w = clamp_width;
    const double x = std::min(t / w, 1.0);
    return { end + sign * w * (x - x * x * x + 0.5 * x * x * x * x), 1 - x * x * (3 - 2 * x),
      -sign * 6 * x * (1 - x) / w };
  }
  /// Where a correction's formula is evaluated for σ: φ(σ) componentwise for smooth_clamp, σ
  /// itself for the expansions (which evaluate it at nearest(σ) through continued_correction).
  /// Δα₁ is evaluated there too (smooth_clamp), so it stays what the data made it near the edge.
  Vec3 formula_stretches(const Vec3& stretches) const {
    if (continuation != Continuation::smooth_clamp)
      return stretches;
    return { smooth_clamp(stretches[0]).value, smooth_clamp(stretches[1]).value,
      smooth_clamp(stretches[2]).value };
  }
  /// smooth_clamp: the point whose first stress and stiffness the correction keeps beyond the
  /// upper (`above`) or lower end, where φ saturates: (end ± w/2, 1, 1), the 1s clamped into the
  /// interval.
  Vec3 end_point(bool above) const {
    const double one = std::clamp(1.0, min, max);
    return { above ? max + 0.5 * clamp_width : min - 0.5 * clamp_width, one, one };
  }
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
  /// Throws InputError(`field`, ...) unless min ≤ max (neither NaN), for bounded_softening and
  /// smooth_clamp K₀ is symmetric positive definite and 0 ≤ β ≤ 1, and for smooth_clamp w > 0.
  void validate(const std::string& field) const {
    if (std::isnan(min) || std::isnan(max) || !(min <= max))
      throw InputError(field, "must be an interval [min, max] with min ≤ max");
    if (continuation != Continuation::edge_hessian) {
      if (!nominal_stiffness.allFinite()
          || (nominal_stiffness - nominal_stiffness.transpose()).norm()
              > 1e-12 * nominal_stiffness.norm()
          || Eigen::LLT<Mat3>(nominal_stiffness).info() != Eigen::Success)
        throw InputError(field, "nominal_stiffness must be symmetric positive definite");
      if (!(kept_stiffness >= 0 && kept_stiffness <= 1))
        throw InputError(field, "kept_stiffness must be in [0, 1]");
    }
    if (continuation == Continuation::smooth_clamp
        && !(std::isfinite(clamp_width) && clamp_width > 0))
      throw InputError(field, "clamp_width must be finite and > 0");
  }
};

/// smooth_clamp: what the correction keeps along one stretch far beyond an end: the first
/// stress N₀ and stiffness ∂N₀/∂σ₀ of its formula at TrustedStretches::end_point, the stiffness
/// bounded below so that the nominal keeps β of its rest shear stiffness 2μ = K₀₀ − K₀₁ (which
/// also bounds its twist there). Zero for an unbounded end.
struct ClampEnd {
  double stress = 0, stiffness = 0;
};
struct ClampEnds {
  ClampEnd above, below;
  /// The end σ is beyond, or null inside.
  const ClampEnd* of(const TrustedStretches& trusted, double s) const {
    return s > trusted.max ? &above : s < trusted.min ? &below : nullptr;
  }
};

/// Computed once by the correction that owns `trusted` (zero for the other continuations).
template <typename Formula>
ClampEnds clamp_ends(const TrustedStretches& trusted, const Formula& formula) {
  ClampEnds out;
  if (trusted.continuation != Continuation::smooth_clamp)
    return out;
  const double floor = -(1 - trusted.kept_stiffness)
      * (trusted.nominal_stiffness(0, 0) - trusted.nominal_stiffness(0, 1));
  for (const bool above : { true, false })
    if (std::isfinite(above ? trusted.max : trusted.min)) {
      Mat3 h;
      ClampEnd& end = above ? out.above : out.below;
      end.stress = formula(trusted.end_point(above), &h)[0];
      end.stiffness = std::max(h(0, 0), floor);
    }
  return out;
}

/// smooth_clamp's continued correction, an exact energy gradient everywhere:
/// ΔΨ_c(σ) = ΔΨ(φ(σ)) + Σᵢ [gᵢ dᵢ + ½ kᵢ dᵢ²], dᵢ = σᵢ − φ(σᵢ), gᵢ and kᵢ the stress and
/// stiffness of the end σᵢ is beyond (dᵢ = 0 inside). So
/// Nᵢ = φ'ᵢ ∂ᵢΔΨ(φ) + (1 − φ'ᵢ)(gᵢ + kᵢ dᵢ) and
/// ∂N/∂σ = D H(φ) D + diag(φ''ᵢ (∂ᵢΔΨ(φ) − gᵢ − kᵢ dᵢ) + kᵢ (1 − φ'ᵢ)²), D = diag(φ'),
/// H = ∇²ΔΨ(φ(σ)). Far beyond an end the correction continues that end's uniaxial stress and
/// stiffness along the stretch beyond, while the other stretches see its formula at points
/// within w/2 of the interval: the tangent is the one of the field N however far the motion
/// goes.
template <typename Formula>
Vec3 smoothly_clamped_correction(const TrustedStretches& trusted, const ClampEnds& ends,
    const Vec3& stretches, Mat3* tangent, const Formula& formula) {
  ClampedStretch c[3];
  Vec3 phi;
  for (int i = 0; i < 3; ++i) {
    c[i] = trusted.smooth_clamp(stretches[i]);
    phi[i] = c[i].value;
  }
  Mat3 h;
  const Vec3 n = formula(phi, tangent != nullptr ? &h : nullptr);
  const Vec3 slope(c[0].slope, c[1].slope, c[2].slope);
  if (tangent != nullptr)
    *tangent = slope.asDiagonal() * h * slope.asDiagonal();
  Vec3 out = slope.cwiseProduct(n);
  for (int i = 0; i < 3; ++i) {
    const ClampEnd* end = ends.of(trusted, stretches[i]);
    if (end == nullptr)
      continue;
    const double d = stretches[i] - phi[i], kept = end->stress + end->stiffness * d;
    out[i] += (1 - slope[i]) * kept;
    if (tangent != nullptr)
      (*tangent)(i, i)
          += c[i].curvature * (n[i] - kept) + end->stiffness * (1 - slope[i]) * (1 - slope[i]);
  }
  return out;
}

/// N at σ, continued beyond `trusted`: `formula(c, hessian)` gives N at c and, if `hessian` is
/// non-null, ∇²ΔΨ(c) there. `tangent` (if non-null) receives ∂N/∂σ (outside: the continued
/// Hessian, TrustedStretches::continued_hessian; for smooth_clamp the exact derivative,
/// smoothly_clamped_correction). `ends` is used by smooth_clamp only.
template <typename Formula>
Vec3 continued_correction(const TrustedStretches& trusted, const ClampEnds& ends,
    const Vec3& stretches, Mat3* tangent, const Formula& formula) {
  const Vec3 c = trusted.nearest(stretches);
  if (c == stretches)
    return formula(stretches, tangent);
  if (trusted.continuation == Continuation::smooth_clamp)
    return smoothly_clamped_correction(trusted, ends, stretches, tangent, formula);
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
double continued_energy(const TrustedStretches& trusted, const ClampEnds& ends,
    const Vec3& stretches, const Energy& energy, const Formula& formula) {
  const Vec3 c = trusted.nearest(stretches);
  if (c == stretches)
    return energy(stretches);
  if (trusted.continuation == Continuation::smooth_clamp) {
    const Vec3 phi = trusted.formula_stretches(stretches);
    double psi = energy(phi);
    for (int i = 0; i < 3; ++i)
      if (const ClampEnd* end = ends.of(trusted, stretches[i])) {
        const double d = stretches[i] - phi[i];
        psi += d * (end->stress + 0.5 * end->stiffness * d);
      }
    return psi;
  }
  Mat3 edge;
  const Vec3 n = formula(c, &edge), d = stretches - c;
  const Mat3 hessian = trusted.continued_hessian(edge);
  return energy(c) + n.dot(d) + 0.5 * d.dot(hessian * d);
}

} // namespace elastolearn::material
