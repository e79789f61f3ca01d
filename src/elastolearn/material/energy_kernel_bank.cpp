#include <elastolearn/core/error.hpp>
#include <elastolearn/material/energy_kernel_bank.hpp>
#include <elastolearn/material/energy_kernel_copies.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <array>

namespace elastolearn::material {

namespace {

/// The slot of the symmetric Hessian entry (a, b): the diagonal 0–2, then (0, 1), (0, 2), (1, 2).
constexpr int symmetric_slot(int a, int b) {
  return a == b ? a : 2 + a + b;
}

} // namespace

EnergyKernelBank::EnergyKernelBank(ConstRef<MatX> centres, double epsilon)
    : m_size(static_cast<int>(centres.rows()))
    , m_epsilon(epsilon) {
  ELASTOLEARN_CHECK(centres.cols() == 3 || centres.rows() == 0, "centres must be m × 3");
  const Eigen::Index padded = (centres.rows() + 3) / 4 * 4;
  // Padding: far-away centres (a finite distance keeps 1/φ finite); their columns are not written.
  for (auto* a : { &m_x, &m_y, &m_z })
    a->setConstant(padded, 1e3);
  if (m_size > 0) {
    m_x.head(m_size) = centres.col(0);
    m_y.head(m_size) = centres.col(1);
    m_z.head(m_size) = centres.col(2);
  }
}

void EnergyKernelBank::evaluate(const Vec3& stretches, Eigen::Ref<Gradients> gradients) const {
  evaluate_packed<false>(stretches, gradients, nullptr);
}

void EnergyKernelBank::evaluate(
    const Vec3& stretches, Eigen::Ref<Gradients> gradients, Eigen::Ref<Hessians> hessians) const {
  evaluate_packed<true>(stretches, gradients, &hessians);
}

template <bool WithHessians>
void EnergyKernelBank::evaluate_packed(
    const Vec3& stretches, Eigen::Ref<Gradients> gradients, Eigen::Ref<Hessians>* hessians) const {
  ELASTOLEARN_CHECK(gradients.cols() == m_size, "gradients need one column per centre");
  if constexpr (WithHessians)
    ELASTOLEARN_CHECK(hessians->cols() == m_size, "hessians need one column per centre");
  // Centre i's copy under π: u = P_π σ, d = u − c_i, φ = √(‖d‖² + ε²); ∂S_i/∂σ[π_j] gains d_j/φ
  // and ∂²S_i/∂σ[π_j]∂σ[π_l] gains δ_jl/φ − d_j d_l/φ³. Lane k of a step is centre 4g + k: one
  // square root and one division per copy, packed (the scalar form's divisions per entry were
  // the forward fit's hottest loop).
  using Lanes = Eigen::Array4d;
  const double eps2 = m_epsilon * m_epsilon;
  const bool smoothed = eps2 > 0;
  for (Eigen::Index first = 0; first < m_size; first += 4) {
    const Lanes cx = m_x.segment<4>(first), cy = m_y.segment<4>(first), cz = m_z.segment<4>(first);
    std::array<Lanes, 3> g;
    std::array<Lanes, 6> h; // symmetric_slot order
    for (auto& a : g)
      a.setZero();
    for (auto& a : h)
      a.setZero();
    for (const auto& pi : kStretchPermutations) {
      const std::array<Lanes, 3> d
          = { stretches[pi[0]] - cx, stretches[pi[1]] - cy, stretches[pi[2]] - cz };
      const Lanes r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2;
      const Lanes inv_phi = inverse_kernels(r2, smoothed); // 0 where ε = 0 at a centre
      for (int j = 0; j < 3; ++j)
        g[pi[j]] += d[j] * inv_phi;
      if constexpr (WithHessians) {
        const Lanes inv3 = inv_phi * inv_phi * inv_phi;
        for (int j = 0; j < 3; ++j) {
          h[pi[j]] += inv_phi - d[j] * d[j] * inv3;
          for (int l = j + 1; l < 3; ++l)
            h[symmetric_slot(pi[j], pi[l])] -= d[j] * d[l] * inv3;
        }
      }
    }
    const Eigen::Index lanes = std::min<Eigen::Index>(4, m_size - first);
    for (Eigen::Index k = 0; k < lanes; ++k) {
      const Eigen::Index i = first + k;
      gradients.col(i) = Vec3(g[0][k], g[1][k], g[2][k]);
      if constexpr (WithHessians) {
        auto column = hessians->col(i);
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r)
            column[3 * c + r] = h[symmetric_slot(std::min(r, c), std::max(r, c))][k];
      }
    }
  }
}

} // namespace elastolearn::material
