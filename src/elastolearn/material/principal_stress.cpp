#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/svd3.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <utility>

namespace elastolearn::material {

namespace {

/// Relative gap below which (P̂ᵢ − P̂ⱼ)/(σᵢ − σⱼ) is replaced by its stable limit, and the
/// floor of σᵢ + σⱼ in (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ). The limit used (trapezoid of the derivatives at σ
/// and at σ with σᵢ, σⱼ swapped) is accurate to O(gap²), the quotient to O(ε/gap): 1e-5 balances
/// both well below 1e-9 relative.
constexpr double quotient_gap = 1e-5;

/// Rows 0..C of column C of H = Y Mᵀ (fixed-size segments, so the loop vectorises).
template <int C> inline void upper_column_of_product(const Mat9& Y, const Mat9& M, Mat9& H) {
  Eigen::Matrix<double, C + 1, 1> h = Y.col(0).template head<C + 1>() * M(C, 0);
  for (int k = 1; k < 9; ++k)
    h += Y.col(k).template head<C + 1>() * M(C, k);
  H.col(C).template head<C + 1>() = h;
}

} // namespace

// A positive-definite matrix (all leading minors > 0, Sylvester) is its own projection: only the
// symmetric part is returned, skipping the eigensolver in the common case.
Mat3 symmetric_psd(const Mat3& A) {
  const Mat3 S = 0.5 * (A + A.transpose());
  const double minor2 = S(0, 0) * S(1, 1) - S(0, 1) * S(0, 1);
  if (S(0, 0) > 0 && minor2 > 0 && S.determinant() > 0)
    return S;
  Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
  const Vec3 lambda = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

PrincipalTangent projected(const PrincipalTangent& t) {
  return { symmetric_psd(t.block), t.twist.cwiseMax(0.0), t.flip.cwiseMax(0.0) };
}

PrincipalFrame principal_frame(const Mat3& F) {
  return svd3(F);
}

Vec3 stretch_rates(const PrincipalFrame& frame, const Mat3& F_rate) {
  Vec3 r;
  for (int k = 0; k < 3; ++k)
    r[k] = frame.U.col(k).dot(F_rate * frame.V.col(k));
  return r;
}

Mat3 first_piola(const PrincipalFrame& frame, const Vec3& principal_stress) {
  return frame.U * principal_stress.asDiagonal() * frame.V.transpose();
}

PrincipalTangent principal_tangent(
    const PrincipalFrame& frame, const Vec3& P, const Mat3& dP, bool project_psd) {
  const Vec3& s = frame.stretches;
  PrincipalTangent t;
  t.block = project_psd ? symmetric_psd(dP) : dP;
  static constexpr int pairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };
  for (int m = 0; m < 3; ++m) {
    const int i = pairs[m][0], j = pairs[m][1];
    const double scale = std::max({ 1.0, std::abs(s[i]), std::abs(s[j]) });
    const double diff = s[i] - s[j];
    // Twist eigenvalue (P̂ᵢ − P̂ⱼ)/(σᵢ − σⱼ), with its limit for σᵢ ≈ σⱼ.
    double twist;
    if (std::abs(diff) > quotient_gap * scale) {
      twist = (P[i] - P[j]) / diff;
    } else {
      twist = 0.5 * ((dP(i, i) - dP(i, j)) + (dP(j, j) - dP(j, i)));
    }
    // Flip eigenvalue (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ); σᵢ + σⱼ ≥ 0 for the canonical frame and is floored.
    double sum = s[i] + s[j];
    if (std::abs(sum) < quotient_gap * scale)
      sum = std::copysign(quotient_gap * scale, sum);
    double flip = (P[i] + P[j]) / sum;
    if (project_psd) {
      twist = std::max(twist, 0.0);
      flip = std::max(flip, 0.0);
    }
    t.twist[m] = twist;
    t.flip[m] = flip;
  }
  return t;
}

PrincipalTangent damping_tangent(
    const PrincipalFrame& frame, const Vec3& P, const Mat3& dP, DampingTangent kind) {
  PrincipalTangent t = principal_tangent(frame, P, dP, false);
  if (kind == DampingTangent::FlipFree)
    t.flip.setZero();
  return t;
}

PrincipalTangent damping_tangent(
    const ElasticModel& model, const PrincipalFrame& frame, DampingTangent kind) {
  return damping_tangent(frame, model.principal_stress(frame.stretches),
      model.principal_stress_derivative(frame.stretches), kind);
}

Mat9 first_piola_derivative(const PrincipalFrame& frame, const PrincipalTangent& t) {
  const Mat3& U = frame.U;
  const Mat3& V = frame.V;
  // In the principal frame, K = d vec(Uᵀ P V) / d vec(Uᵀ F V) has the 3×3 block A = ∂P̂/∂σ on
  // the diagonal entries and, per pair (i, j), the 2×2 block [a b; b a] on the entries (i,j),
  // (j,i), whose eigenvectors (1, ±1)/√2 carry the twist and flip eigenvalues. With
  // W = kron(V, U) (columns vec(u_k v_lᵀ)), dP/dF = W K Wᵀ is therefore the sum of
  //   G A Gᵀ,  G's column k = vec(u_k v_kᵀ),
  //   ½ twist · m₊ m₊ᵀ + ½ flip · m₋ m₋ᵀ per pair,  m± = vec(u_i v_jᵀ ± u_j v_iᵀ):
  // H = Y Mᵀ with M = [G | m₊ | m₋] and Y = [G A | ½ twist m₊ | ½ flip m₋]; no 9×9×9×9 work.
  Mat9 M, Y;
  for (int k = 0; k < 3; ++k)
    for (int b = 0; b < 3; ++b)
      M.col(k).segment<3>(3 * b) = V(b, k) * U.col(k);
  Y.leftCols<3>().noalias() = M.leftCols<3>() * t.block;
  static constexpr int pairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };
  for (int m = 0; m < 3; ++m) {
    const int i = pairs[m][0], j = pairs[m][1];
    for (int b = 0; b < 3; ++b) {
      const Vec3 p = V(b, j) * U.col(i); // vec(u_i v_jᵀ), rows 3b..3b+2
      const Vec3 q = V(b, i) * U.col(j); // vec(u_j v_iᵀ)
      M.col(3 + m).segment<3>(3 * b) = p + q;
      M.col(6 + m).segment<3>(3 * b) = p - q;
    }
    Y.col(3 + m) = (0.5 * t.twist[m]) * M.col(3 + m);
    Y.col(6 + m) = (0.5 * t.flip[m]) * M.col(6 + m);
  }
  Mat9 H;
  if (t.block == t.block.transpose()) {
    // A symmetric block makes H symmetric: build its upper triangle and mirror it.
    [&]<int... C>(std::integer_sequence<int, C...>) {
      (upper_column_of_product<C>(Y, M, H), ...);
    }
    (std::make_integer_sequence<int, 9>());
    H.triangularView<Eigen::StrictlyLower>() = H.transpose();
  } else {
    for (int c = 0; c < 9; ++c) {
      Vec9 h = Y.col(0) * M(c, 0);
      for (int k = 1; k < 9; ++k)
        h += Y.col(k) * M(c, k);
      H.col(c) = h;
    }
  }
  return H;
}

Mat9 first_piola_derivative(
    const PrincipalFrame& frame, const Vec3& P, const Mat3& dP, bool project_psd) {
  return first_piola_derivative(frame, principal_tangent(frame, P, dP, project_psd));
}

Mat3 first_piola_differential(
    const PrincipalFrame& frame, const PrincipalTangent& t, const Mat3& dF) {
  const Mat3 local = frame.U.transpose() * dF * frame.V;
  Mat3 dP_local;
  dP_local.diagonal() = t.block * local.diagonal();
  static constexpr int pairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };
  for (int m = 0; m < 3; ++m) {
    const int i = pairs[m][0], j = pairs[m][1];
    const double twist_part = 0.5 * t.twist[m] * (local(i, j) + local(j, i));
    const double flip_part = 0.5 * t.flip[m] * (local(i, j) - local(j, i));
    dP_local(i, j) = twist_part + flip_part;
    dP_local(j, i) = twist_part - flip_part;
  }
  return frame.U * dP_local * frame.V.transpose();
}

Mat9 first_piola_rate_derivative(const PrincipalFrame& frame, const Mat3& d_stretch_rates) {
  // P = Σᵢ Nᵢ uᵢ vᵢᵀ and Ḟ̂ₖ = uₖᵀ Ḟ vₖ = ⟨uₖ vₖᵀ, Ḟ⟩, so ∂vec P/∂vec Ḟ = G (∂N/∂Ḟ̂) Gᵀ with
  // G's column k = vec(uₖ vₖᵀ).
  Eigen::Matrix<double, 9, 3> G;
  for (int k = 0; k < 3; ++k)
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a)
        G(a + 3 * b, k) = frame.U(a, k) * frame.V(b, k);
  return G * d_stretch_rates * G.transpose();
}

CorrectedStress corrected_principal_stress(const ElasticModel& model, const Correction* correction,
    const Vec3& stretches, const Vec3& stretch_rates) {
  CorrectedStress out { model.principal_stress(stretches),
    model.principal_stress_derivative(stretches), Mat3::Zero() };
  if (correction != nullptr) {
    Mat3 dn_ds, dn_dr;
    out.stress += correction->correction_with_gradient(stretches, stretch_rates, dn_ds, dn_dr);
    out.d_stretches += dn_ds;
    out.d_stretch_rates = dn_dr;
  }
  return out;
}

Mat3 first_piola(const ElasticModel& model, const Mat3& F) {
  const PrincipalFrame frame = principal_frame(F);
  return first_piola(frame, model.principal_stress(frame.stretches));
}

PrincipalTangent principal_tangent(
    const ElasticModel& model, const PrincipalFrame& frame, bool project_psd) {
  return principal_tangent(frame, model.principal_stress(frame.stretches),
      model.principal_stress_derivative(frame.stretches), project_psd);
}

Mat9 first_piola_derivative(const ElasticModel& model, const Mat3& F, bool project_psd) {
  const PrincipalFrame frame = principal_frame(F);
  return first_piola_derivative(frame, model.principal_stress(frame.stretches),
      model.principal_stress_derivative(frame.stretches), project_psd);
}

double energy(const ElasticModel& model, const Mat3& F) {
  return model.energy(principal_frame(F).stretches);
}

} // namespace elastolearn::material
