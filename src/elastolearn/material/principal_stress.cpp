#include <elastolearn/material/principal_stress.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

namespace elastolearn::material {

namespace {

/// Relative gap below which (P̂ᵢ − P̂ⱼ)/(σᵢ − σⱼ) is replaced by its stable limit, and the
/// floor of σᵢ + σⱼ in (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ). The limit used (trapezoid of the derivatives at σ
/// and at σ with σᵢ, σⱼ swapped) is accurate to O(gap²), the quotient to O(ε/gap): 1e-5 balances
/// both well below 1e-9 relative.
constexpr double quotient_gap = 1e-5;

/// Symmetrise a 3×3 matrix and clamp its negative eigenvalues to zero.
Mat3 project_psd_3x3(const Mat3& A) {
    const Mat3 S = 0.5 * (A + A.transpose());
    Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
    const Vec3 lambda = eig.eigenvalues().cwiseMax(0.0);
    return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

/// kron(V, U): vec(U X Vᵀ) = kron(V, U) vec(X) for column-major vec.
Mat9 kron_vu(const Mat3& U, const Mat3& V) {
    Mat9 W;
    for (int l = 0; l < 3; ++l)
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                for (int i = 0; i < 3; ++i)
                    W(i + 3 * j, k + 3 * l) = U(i, k) * V(j, l);
    return W;
}

} // namespace

PrincipalFrame principal_frame(const Mat3& F) {
    const Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    PrincipalFrame frame { svd.matrixU(), svd.singularValues(), svd.matrixV() };
    // Singular values come sorted descending and non-negative; make U and V proper rotations by
    // negating the column of the smallest stretch (and the stretch itself), Irving et al. 2004.
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

Vec3 stretch_rates(const PrincipalFrame& frame, const Mat3& F_rate) {
    Vec3 r;
    for (int k = 0; k < 3; ++k)
        r[k] = frame.U.col(k).dot(F_rate * frame.V.col(k));
    return r;
}

Mat3 first_piola(const PrincipalFrame& frame, const Vec3& principal_stress) {
    return frame.U * principal_stress.asDiagonal() * frame.V.transpose();
}

Mat9 first_piola_derivative(
    const PrincipalFrame& frame, const Vec3& P, const Mat3& dP, bool project_psd) {
    const Vec3& s = frame.stretches;
    // K = d vec(Uᵀ P V) / d vec(Uᵀ F V) in the principal frame: the 3×3 block on the diagonal
    // entries (vec indices 0, 4, 8) and one 2×2 block per pair (i, j) on the entries (i,j), (j,i).
    Mat9 K = Mat9::Zero();
    const Mat3 A = project_psd ? project_psd_3x3(dP) : dP;
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            K(4 * i, 4 * j) = A(i, j);
    static constexpr int pairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };
    for (const auto& pair : pairs) {
        const int i = pair[0], j = pair[1];
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
        const double a = 0.5 * (twist + flip), b = 0.5 * (twist - flip);
        const int p = i + 3 * j, q = j + 3 * i;
        K(p, p) = a;
        K(q, q) = a;
        K(p, q) = b;
        K(q, p) = b;
    }
    const Mat9 W = kron_vu(frame.U, frame.V);
    return W * K * W.transpose();
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
        correction->correction_gradient(stretches, stretch_rates, dn_ds, dn_dr);
        out.stress += correction->correction(stretches, stretch_rates);
        out.d_stretches += dn_ds;
        out.d_stretch_rates = dn_dr;
    }
    return out;
}

Mat3 first_piola(const ElasticModel& model, const Mat3& F) {
    const PrincipalFrame frame = principal_frame(F);
    return first_piola(frame, model.principal_stress(frame.stretches));
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
