#pragma once
/// \file Fast, accurate SVD of a 3×3 matrix for the per-element material kernel: one-sided
/// (Hestenes) Jacobi on the columns of F, run to convergence, then the inversion-safe sign
/// convention of PrincipalFrame (Irving et al. 2004). One-sided Jacobi is backward stable and
/// computes every singular value to high relative accuracy (Demmel & Veselić 1992), so it keeps
/// the accuracy of Eigen's JacobiSVD at about a tenth of its cost.
#include <elastolearn/core/types.hpp>

namespace elastolearn::material {

struct PrincipalFrame;

/// Diagnostics of one svd3 call (for tests and benchmarks).
struct Svd3Info {
  int sweeps = 0; ///< Jacobi sweeps over the 3 column pairs, including the final check
  int rotations = 0; ///< plane rotations applied
  bool fallback = false; ///< true if Jacobi did not converge and Eigen::JacobiSVD was used
};

/// F = U diag(σ) Vᵀ with U, V proper rotations, |σ| sorted descending, σ₀, σ₁ ≥ 0 and σ₂ < 0
/// exactly when det F < 0 (up to rounding). Columns are orthogonalised until every pair of
/// columns of F V has cosine ≤ 1e-15 (≈ 4.5 ε), so ‖UᵀU − I‖, ‖VᵀV − I‖ and
/// ‖U diag(σ) Vᵀ − F‖ / ‖F‖ are all a few ε. Exact zero, rank-one and rank-two F are handled
/// (the missing directions of U are completed orthonormally). Inputs of any finite magnitude are
/// scaled by a power of two internally (no overflow or underflow); a non-finite F gives NaNs.
/// Allocation-free. `info`, if given, receives iteration counts.
PrincipalFrame svd3(const Mat3& F, Svd3Info* info = nullptr);

} // namespace elastolearn::material
