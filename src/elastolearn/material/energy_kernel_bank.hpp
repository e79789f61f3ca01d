#pragma once
/// \file The energy kernels S_i of many centres evaluated together (energy_kernel_gradient of each
/// centre, packed four centres per step): the columns of a design matrix whose unknowns are the
/// kernels' weights (learn::RbfDesign), built once per element and frame by the forward fit's
/// sensitivities and the loop's reconstruction.
#include <elastolearn/core/types.hpp>

namespace elastolearn::material {

class EnergyKernelBank {
  public:
  using Gradients = Eigen::Matrix<double, 3, Eigen::Dynamic>;
  using Hessians = Eigen::Matrix<double, 9, Eigen::Dynamic>;

  EnergyKernelBank() = default;
  /// `centres` m × 3 (m ≥ 0, finite), ε ≥ 0 the kernels' smoothing (rbf_kernel).
  EnergyKernelBank(ConstRef<MatX> centres, double epsilon);

  int size() const { return m_size; }

  /// ∇S_i(σ) into gradients.col(i) (3 × size()): energy_kernel_gradient of each centre up to
  /// round-off (the same sum over the six permutations in the same order, with 1/φ formed once
  /// per copy). Allocation-free.
  void evaluate(const Vec3& stretches, Eigen::Ref<Gradients> gradients) const;
  /// The same, and ∇²S_i(σ) reshaped column-major into hessians.col(i) (9 × size()).
  void evaluate(
      const Vec3& stretches, Eigen::Ref<Gradients> gradients, Eigen::Ref<Hessians> hessians) const;

  private:
  template <bool WithHessians>
  void evaluate_packed(
      const Vec3& stretches, Eigen::Ref<Gradients> gradients, Eigen::Ref<Hessians>* hessians) const;

  int m_size = 0;
  double m_epsilon = 0;
  /// The centres' coordinates, padded to a multiple of four with far-away copies (never written
  /// out).
  Eigen::ArrayXd m_x, m_y, m_z;
};

} // namespace elastolearn::material
