#pragma once
/// \file The bounded continuation's Hessian (material::Continuation::bounded_softening) computed
/// independently of material/trusted_stretches.hpp: through the generalized eigenproblem
/// H v = λ K₀ v with Vᵀ K₀ V = I, so that H = K₀ V Λ Vᵀ K₀, with λ raised to at least β − 1.
#include <elastolearn/core/types.hpp>

#include <Eigen/Eigenvalues>

namespace elastolearn::test {

inline Mat3 bounded_hessian(const Mat3& edge_hessian, const Mat3& k0, double beta) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> g(edge_hessian, k0);
  return k0 * g.eigenvectors() * g.eigenvalues().cwiseMax(beta - 1).asDiagonal()
      * g.eigenvectors().transpose() * k0;
}

} // namespace elastolearn::test
