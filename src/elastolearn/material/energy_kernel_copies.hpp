#pragma once
/// \file The weighted energy kernels of an RBF correction, as plain kernels in σ-space, packed
/// for the simulator's hottest loop: Σ_i w_i S_i(σ) with S_i(σ) = Σ_π φ(‖σ − P_π⁻¹ c_i‖) is a sum
/// of φ over the six permuted copies of every centre (rbf_correction.hpp).
#include <elastolearn/core/types.hpp>

namespace elastolearn::material {

/// 1/φ of four kernels from their r² = ‖d‖² + ε², and 0 where r² = 0 (ε = 0 at a centre: the
/// subgradient 0). With ε > 0 (`smoothed`) r² > 0 everywhere and the square roots and divisions
/// run packed; Eigen 3.4's select runs coefficient-wise, and so does every operation inside it.
inline Eigen::Array4d inverse_kernels(const Eigen::Array4d& r2, bool smoothed) {
  if (smoothed)
    return r2.sqrt().inverse();
  return (r2 > 0).select(r2.sqrt().inverse(), 0.0);
}

class EnergyKernelCopies {
  public:
  EnergyKernelCopies() = default;
  /// The six permuted copies of every centre (m × 3), each with its centre's weight (m).
  EnergyKernelCopies(ConstRef<MatX> centres, ConstRef<VecX> weights, double epsilon);

  bool empty() const { return m_w.size() == 0; }

  /// Σ_j w_j ∇φ_j(σ) over the copies j and, if `hessian` is not null, Σ_j w_j ∇²φ_j(σ) added to
  /// it. With ε = 0, a copy at σ adds nothing (the subgradient 0). Allocation-free; on x86-64
  /// with AVX (checked at run time) four copies per instruction, bit for bit the result of
  /// gradient_sum_portable.
  Vec3 gradient_sum(const Vec3& stretches, Mat3* hessian) const;
  /// The same with Eigen's packets of the compile-time target (SSE2 on x86-64): two copies per
  /// instruction. Public so that tests can compare the two paths.
  Vec3 gradient_sum_portable(const Vec3& stretches, Mat3* hessian) const;
  /// True if gradient_sum runs the AVX path on this machine.
  static bool uses_avx();

  private:
  /// The copies in structure-of-arrays form, padded to a multiple of 4 with far-away copies of
  /// zero weight (a finite distance keeps 1/φ finite).
  Eigen::ArrayXd m_x, m_y, m_z, m_w;
  double m_epsilon = 0;
};

} // namespace elastolearn::material
