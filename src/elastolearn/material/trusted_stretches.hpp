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
/// Continuation::smooth_expansion (`learn --continuation smooth_expansion`) is the smooth clamp
/// with ΔΨ(φ(σ)) expanded to second order in the distances beyond, its gradient and Hessian
/// taken from the ends' with constant coefficients: exact for a quadratic ΔΨ, whose stiffness
/// the transition keeps, and coupling a stretch beyond to the others as the edge's Hessian does,
/// still with no third derivative of ΔΨ in its exact tangent (smoothly_clamped_correction).
///
/// The bounded_softening and edge_hessian expansions are exact energies where every stretch is
/// beyond the same end. Where some stretches are beyond an end and others inside, c moves with the
/// inside ones, and ∂N/∂σ then holds third derivatives of ΔΨ times the distance beyond the end that
/// the tangent H leaves out: Newton's matrix and the stability check see a stiffness the stress
/// field does not have (seed 12's case 12 of the random benchmark stalled that way; both smooth
/// forms complete it).
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/types.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace elastolearn::material {

/// How ΔΨ is continued beyond the trusted stretches (the file's "continuation").
enum class Continuation {
  edge_hessian, ///< with the edge's Hessian ∇²ΔΨ(c) (files written before "continuation")
  bounded_softening, ///< with it bounded below: K₀ + H ⪰ β K₀
  smooth_clamp, ///< ΔΨ(φ(σ)) + each end's uniaxial stress and stiffness beyond it (exact)
  /// ΔΨ(φ(σ)) + its second-order expansion in the distances beyond, the ends' whole stiffness
  /// (exact)
  smooth_expansion,
};

/// Every continuation, in the order their names are listed.
inline constexpr Continuation kContinuations[] = { Continuation::edge_hessian,
  Continuation::bounded_softening, Continuation::smooth_clamp, Continuation::smooth_expansion };

/// The continuation's name in files and options ("edge_hessian", "bounded_softening",
/// "smooth_clamp", "smooth_expansion").
inline const char* continuation_name(Continuation c) {
  switch (c) {
  case Continuation::edge_hessian:
    return "edge_hessian";
  case Continuation::bounded_softening:
    return "bounded_softening";
  case Continuation::smooth_clamp:
    return "smooth_clamp";
  case Continuation::smooth_expansion:
    return "smooth_expansion";
  }
  return "edge_hessian";
}

/// Every continuation's name (kContinuations' order).
inline std::vector<std::string> continuation_names() {
  std::vector<std::string> names;
  for (const Continuation c : kContinuations)
    names.emplace_back(continuation_name(c));
  return names;
}

/// The continuation named `name`; throws InputError(`field`, ...) naming the choices otherwise.
inline Continuation continuation_from_name(const std::string& name, const std::string& field) {
  std::string expected;
  for (const Continuation c : kContinuations) {
    if (name == continuation_name(c))
      return c;
    const char* separator = c == kContinuations[std::size(kContinuations) - 1] ? " or " : ", ";
    expected.append(expected.empty() ? "" : separator).append(continuation_name(c));
  }
  throw InputError(field, "unknown continuation \"" + name + "\" (expected " + expected + ")");
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
  /// All but edge_hessian: K₀, the nominal's ∂P̂/∂σ at rest (symmetric positive
  /// definite) [Pa], and β ∈ [0, 1].
  Mat3 nominal_stiffness = Mat3::Zero();
  double kept_stiffness = kKeptStiffness;
  /// smooth_clamp and smooth_expansion: the transition width w [-] (> 0).
  double clamp_width = kClampWidth;

  bool bounded() const { return std::isfinite(min) || std::isfinite(max); }
  /// Whether the continuation goes through the smooth clamp φ (smooth_clamp, smooth_expansion).
  bool smooth() const {
    return continuation == Continuation::smooth_clamp
        || continuation == Continuation::smooth_expansion;
  }
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
  /// Where a correction's formula is evaluated for σ: φ(σ) componentwise for the smooth forms,
  /// σ itself for the others (which evaluate it at nearest(σ) through continued_correction).
  /// Δα₁ is evaluated there too (smooth forms), so it stays what the data made it near the edge.
  Vec3 formula_stretches(const Vec3& stretches) const {
    if (!smooth())
      return stretches;
    return { smooth_clamp(stretches[0]).value, smooth_clamp(stretches[1]).value,
      smooth_clamp(stretches[2]).value };
  }
  /// Smooth forms: the point whose first stress and stiffness the correction keeps beyond the
  /// upper (`above`) or lower end, where φ saturates: (end ± w/2, 1, 1), the 1s clamped into the
  /// interval.
  Vec3 end_point(bool above) const {
    return { above ? max + 0.5 * clamp_width : min - 0.5 * clamp_width, one(), one() };
  }
  /// smooth_expansion: the point of two stretches beyond ends, the first beyond the upper
  /// (`above0`) or lower end, the second beyond `above1`'s: (end₀ ± w/2, end₁ ± w/2, 1').
  Vec3 pair_point(bool above0, bool above1) const {
    Vec3 p = end_point(above0);
    p[1] = end_point(above1)[0];
    return p;
  }
  /// 1 clamped into [min, max] (1'): the end points' other stretches.
  double one() const { return std::clamp(1.0, min, max); }
  /// Whether the upper (`above`) or lower end is finite.
  bool has_end(bool above) const { return std::isfinite(above ? max : min); }
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
  /// Throws InputError(`field`, ...) unless min ≤ max (neither NaN), for all but edge_hessian K₀
  /// is symmetric positive definite and 0 ≤ β ≤ 1, and for the smooth forms w > 0.
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
    if (smooth() && !(std::isfinite(clamp_width) && clamp_width > 0))
      throw InputError(field, "clamp_width must be finite and > 0");
  }
};

/// The smooth forms: what the correction keeps along one stretch far beyond an end, from its
/// formula at TrustedStretches::end_point (end ± w/2, 1', 1'): the first stress g = N₀ and
/// stiffness k = ∂N₀/∂σ₀, k bounded below so that the nominal keeps β of its rest shear stiffness
/// 2μ = K₀₀ − K₀₁ (which also bounds its twist there), and (smooth_expansion) the coupling
/// l = ∂N₀/∂σ₁ to the other stretches, k and l from the Hessian there bounded as
/// TrustedStretches::continued_hessian bounds it. Zero for an unbounded end.
struct ClampEnd {
  double stress = 0, stiffness = 0, coupling = 0;
};
struct ClampEnds {
  ClampEnd above, below;
  /// smooth_expansion: m = ∂N₀/∂σ₁ of the formula where two stretches are beyond ends: [0]
  /// above, [1] below, at (end₀ ± w/2, end₁ ± w/2, 1'), from the bounded Hessian there.
  double pair[2][2] = { { 0, 0 }, { 0, 0 } };
  /// f: 1 for smooth_expansion, whose expansion follows φ (the term k f (φ − p) below), 0 for
  /// smooth_clamp, which expands at the end point itself.
  double follow = 0;
  /// The end σ is beyond, or null inside.
  const ClampEnd* of(const TrustedStretches& trusted, double s) const {
    return s > trusted.max ? &above : s < trusted.min ? &below : nullptr;
  }
  /// 0 for a stretch beyond the upper end, 1 for the lower (σ beyond one).
  static int side(const TrustedStretches& trusted, double s) { return s > trusted.max ? 0 : 1; }
};

/// Computed once by the correction that owns `trusted` (zero for the other continuations).
template <typename Formula>
ClampEnds clamp_ends(const TrustedStretches& trusted, const Formula& formula) {
  ClampEnds out;
  if (!trusted.smooth())
    return out;
  const double floor = -(1 - trusted.kept_stiffness)
      * (trusted.nominal_stiffness(0, 0) - trusted.nominal_stiffness(0, 1));
  const bool expansion = trusted.continuation == Continuation::smooth_expansion;
  Mat3 h;
  for (const bool above : { true, false })
    if (trusted.has_end(above)) {
      ClampEnd& end = above ? out.above : out.below;
      end.stress = formula(trusted.end_point(above), &h)[0];
      if (expansion) // the end's whole stiffness, bounded as bounded_softening bounds it
        h = trusted.continued_hessian(h);
      end.stiffness = std::max(h(0, 0), floor);
      end.coupling = expansion ? h(0, 1) : 0;
    }
  if (!expansion)
    return out;
  out.follow = 1;
  for (int a = 0; a < 2; ++a)
    for (int b = a; b < 2; ++b)
      if (trusted.has_end(a == 0) && trusted.has_end(b == 0)) {
        formula(trusted.pair_point(a == 0, b == 0), &h);
        out.pair[a][b] = out.pair[b][a] = trusted.continued_hessian(h)(0, 1);
      }
  return out;
}

/// The smooth forms' continued correction, an exact energy gradient everywhere. With φ the smooth
/// clamp, dᵢ = σᵢ − φᵢ (zero inside), uᵢ = φᵢ − 1', pᵢ the coordinate of the end point of the end
/// σᵢ is beyond, B the stretches beyond an end, and g, k, l, m, f of ClampEnds:
/// ΔΨ_c(σ) = ΔΨ(φ) + Σ_{i∈B} dᵢ [gᵢ + kᵢ (f (φᵢ − pᵢ) + ½ dᵢ) + lᵢ Σ_{j≠i} uⱼ] + Σ_{i<j∈B} mᵢⱼ dᵢ
/// dⱼ. smooth_expansion (f = 1) is ΔΨ(φ) expanded to second order in the distances beyond, its
/// gradient at φ and its Hessian taken from the end points' with constant coefficients, so it is
/// exact for a quadratic ΔΨ (the transition keeps its stiffness) and its exact tangent holds no
/// third derivative of ΔΨ; smooth_clamp (f = l = m = 0) keeps each end's uniaxial stress and
/// stiffness at the end point. So N_q = φ'_q (n_q + b_q) + (1 − φ'_q) a_q, n = ∇ΔΨ(φ),
/// a_q = g_q + k_q (f (φ_q − p_q) + d_q) + l_q U_q + Σ_{j∈B≠q} m_qj d_j, U_q = Σ_{j≠q} u_j,
/// b_q = f k_q d_q + Σ_{i∈B≠q} l_i d_i (the terms in k only for q ∈ B), and
/// ∂N/∂σ = D H(φ) D + diag(φ''_q (n_q + b_q − a_q) + k_q (1 − φ'_q)(1 − φ'_q + 2 f φ'_q)) + off
/// the diagonal (1 − φ'_q) l_q φ'_r + φ'_q (1 − φ'_r) l_r + (1 − φ'_q)(1 − φ'_r) m_qr,
/// D = diag(φ'), H = ∇²ΔΨ(φ). Far beyond an end the stretch beyond continues the end's stress and
/// stiffness (and couples to the others through l), while the formula is read within w/2 of the
/// interval.
template <typename Formula>
Vec3 smoothly_clamped_correction(const TrustedStretches& trusted, const ClampEnds& ends,
    const Vec3& stretches, Mat3* tangent, const Formula& formula) {
  ClampedStretch c[3];
  const ClampEnd* end[3];
  int side[3];
  Vec3 phi, d, u;
  for (int i = 0; i < 3; ++i) {
    c[i] = trusted.smooth_clamp(stretches[i]);
    phi[i] = c[i].value;
    end[i] = ends.of(trusted, stretches[i]);
    side[i] = end[i] != nullptr ? ClampEnds::side(trusted, stretches[i]) : -1;
    d[i] = stretches[i] - phi[i];
    u[i] = phi[i] - trusted.one();
  }
  Mat3 h;
  const Vec3 n = formula(phi, tangent != nullptr ? &h : nullptr);
  const Vec3 slope(c[0].slope, c[1].slope, c[2].slope);
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  for (int q = 0; q < 3; ++q)
    for (int i = 0; i < 3; ++i) {
      if (i == q || end[i] == nullptr)
        continue;
      b[q] += end[i]->coupling * d[i];
      if (end[q] != nullptr)
        a[q] += ends.pair[side[q]][side[i]] * d[i];
    }
  for (int q = 0; q < 3; ++q)
    if (end[q] != nullptr) {
      const double from_end = phi[q] - trusted.end_point(side[q] == 0)[0];
      a[q] += end[q]->stress + end[q]->stiffness * (ends.follow * from_end + d[q])
          + end[q]->coupling * (u.sum() - u[q]);
      b[q] += ends.follow * end[q]->stiffness * d[q];
    }
  const Vec3 out = slope.cwiseProduct(n + b) + (Vec3::Ones() - slope).cwiseProduct(a);
  if (tangent != nullptr) {
    *tangent = slope.asDiagonal() * h * slope.asDiagonal();
    for (int q = 0; q < 3; ++q) {
      if (end[q] != nullptr)
        (*tangent)(q, q) += c[q].curvature * (n[q] + b[q] - a[q])
            + end[q]->stiffness * (1 - slope[q]) * (1 - slope[q] + 2 * ends.follow * slope[q]);
      for (int r = 0; r < 3; ++r) {
        if (r == q)
          continue;
        if (end[q] != nullptr)
          (*tangent)(q, r) += (1 - slope[q]) * end[q]->coupling * slope[r];
        if (end[r] != nullptr)
          (*tangent)(q, r) += slope[q] * (1 - slope[r]) * end[r]->coupling;
        if (end[q] != nullptr && end[r] != nullptr)
          (*tangent)(q, r) += (1 - slope[q]) * (1 - slope[r]) * ends.pair[side[q]][side[r]];
      }
    }
  }
  return out;
}

/// N at σ, continued beyond `trusted`: `formula(c, hessian)` gives N at c and, if `hessian` is
/// non-null, ∇²ΔΨ(c) there. `tangent` (if non-null) receives ∂N/∂σ (outside: the continued
/// Hessian, TrustedStretches::continued_hessian; for the smooth forms the exact derivative,
/// smoothly_clamped_correction). `ends` is used by the smooth forms only.
template <typename Formula>
Vec3 continued_correction(const TrustedStretches& trusted, const ClampEnds& ends,
    const Vec3& stretches, Mat3* tangent, const Formula& formula) {
  const Vec3 c = trusted.nearest(stretches);
  if (c == stretches)
    return formula(stretches, tangent);
  if (trusted.smooth())
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
  if (trusted.smooth()) {
    const Vec3 phi = trusted.formula_stretches(stretches), d = stretches - phi;
    const double u_sum = (phi.array() - trusted.one()).sum();
    double psi = energy(phi);
    for (int i = 0; i < 3; ++i)
      if (const ClampEnd* end = ends.of(trusted, stretches[i])) {
        const double u_others = u_sum - (phi[i] - trusted.one());
        const double from_end = phi[i] - trusted.end_point(stretches[i] > trusted.max)[0];
        psi += d[i]
            * (end->stress + end->stiffness * (ends.follow * from_end + 0.5 * d[i])
                + end->coupling * u_others);
        for (int j = i + 1; j < 3; ++j)
          if (ends.of(trusted, stretches[j]) != nullptr)
            psi += ends.pair[ClampEnds::side(trusted, stretches[i])]
                            [ClampEnds::side(trusted, stretches[j])]
                * d[i] * d[j];
      }
    return psi;
  }
  Mat3 edge;
  const Vec3 n = formula(c, &edge), d = stretches - c;
  const Mat3 hessian = trusted.continued_hessian(edge);
  return energy(c) + n.dot(d) + 0.5 * d.dot(hessian * d);
}

} // namespace elastolearn::material
