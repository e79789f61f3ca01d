// EnergyKernelBank: the packed energy kernels equal energy_kernel_gradient of each centre (up to
// round-off), their gradient is the derivative of the kernel energy and their Hessian that of the
// gradient (central differences), with a centre count that leaves the last packed step partial.
#include <elastolearn/material/energy_kernel_bank.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace elastolearn;
using namespace elastolearn::material;

namespace {

MatX random_centres(int m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.6, 1.5);
  MatX c(m, 3);
  for (int i = 0; i < m; ++i)
    c.row(i) << u(rng), u(rng), u(rng);
  return c;
}

} // namespace

TEST(EnergyKernelBank, EqualsEachCentresScalarKernel) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.5, 1.7);
  for (const int m : { 1, 4, 7 }) // 7: the last packed step holds three centres
    for (const double epsilon : { 0.0, 0.05 }) {
      const MatX centres = random_centres(m, rng);
      const EnergyKernelBank bank(centres, epsilon);
      ASSERT_EQ(bank.size(), m);
      EnergyKernelBank::Gradients gradients(3, m), gradients_only(3, m);
      EnergyKernelBank::Hessians hessians(9, m);
      for (int trial = 0; trial < 20; ++trial) {
        const Vec3 s(u(rng), u(rng), u(rng));
        bank.evaluate(s, gradients, hessians);
        bank.evaluate(s, gradients_only);
        for (int i = 0; i < m; ++i) {
          Mat3 hessian;
          const Vec3 g = energy_kernel_gradient(s, centres.row(i).transpose(), epsilon, &hessian);
          // Sums of six O(1) terms (the Hessian's of O(1/φ) ≤ ~10): round-off only.
          EXPECT_LT((gradients.col(i) - g).norm(), 1e-13 * (1 + g.norm()))
              << "m " << m << " i " << i;
          EXPECT_EQ(gradients_only.col(i), gradients.col(i));
          EXPECT_LT((hessians.col(i) - hessian.reshaped()).norm(), 1e-12 * (1 + hessian.norm()))
              << "m " << m << " i " << i;
        }
      }
    }
}

TEST(EnergyKernelBank, GradientAndHessianAreDerivatives) {
  std::mt19937 rng(11);
  const int m = 6;
  const double epsilon = 0.1;
  const MatX centres = random_centres(m, rng);
  const EnergyKernelBank bank(centres, epsilon);
  const Vec3 s(1.21, 0.93, 0.78);
  EnergyKernelBank::Gradients g(3, m), g_plus(3, m), g_minus(3, m);
  EnergyKernelBank::Hessians h(9, m), unused(9, m);
  bank.evaluate(s, g, h);
  const double step = 1e-5;
  for (int j = 0; j < 3; ++j) {
    const Vec3 e = step * Vec3::Unit(j);
    bank.evaluate(s + e, g_plus, unused);
    bank.evaluate(s - e, g_minus, unused);
    for (int i = 0; i < m; ++i) {
      const Vec3 c = centres.row(i).transpose();
      // Central differences: O(step²) truncation (third derivatives ≲ 1/ε² = 100) plus
      // round-off O(1e-16 / step): both far below 1e-6.
      const double d_energy
          = (energy_kernel(s + e, c, epsilon) - energy_kernel(s - e, c, epsilon)) / (2 * step);
      EXPECT_NEAR(g(j, i), d_energy, 1e-6) << "kernel " << i << " direction " << j;
      const Vec3 d_gradient = (g_plus.col(i) - g_minus.col(i)) / (2 * step);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(h(3 * j + k, i), d_gradient[k], 1e-6)
            << "kernel " << i << " (" << k << ", " << j << ")";
    }
  }
}

TEST(EnergyKernelBank, AtACentreWithoutSmoothingTheCopyAddsNothing) {
  // ε = 0 and σ on a centre: that copy's φ = 0, its subgradient 0, as the scalar kernel's.
  MatX centres(2, 3);
  centres << 1.2, 0.9, 0.8, 1.0, 1.1, 0.7;
  const EnergyKernelBank bank(centres, 0.0);
  EnergyKernelBank::Gradients g(3, 2);
  EnergyKernelBank::Hessians h(9, 2);
  const Vec3 s = centres.row(0).transpose();
  bank.evaluate(s, g, h);
  EXPECT_TRUE(g.allFinite());
  EXPECT_TRUE(h.allFinite());
  Mat3 hessian;
  const Vec3 scalar = energy_kernel_gradient(s, s, 0.0, &hessian);
  EXPECT_LT((g.col(0) - scalar).norm(), 1e-13);
  EXPECT_LT((h.col(0) - hessian.reshaped()).norm(), 1e-12);
}

TEST(EnergyKernelBank, NoCentresIsEmpty) {
  const EnergyKernelBank bank(MatX(0, 3), 0.1);
  EnergyKernelBank::Gradients g(3, 0);
  EnergyKernelBank::Hessians h(9, 0);
  bank.evaluate(Vec3(1.1, 1, 0.9), g, h);
  EXPECT_EQ(bank.size(), 0);
}
