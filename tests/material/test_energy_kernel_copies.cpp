// EnergyKernelCopies: the packed sum of the weighted energy kernels equals the sum of each
// centre's energy_kernel_gradient (up to round-off), and its run-time AVX path gives the portable
// path's result bit for bit, with and without the Hessian, for centre counts that leave the last
// packed step partial.
#include <elastolearn/material/energy_kernel_copies.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace elastolearn;
using namespace elastolearn::material;

namespace {

struct Kernels {
  MatX centres;
  VecX weights;
};

Kernels random_kernels(int m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.6, 1.5);
  std::normal_distribution<double> g(0.0, 1e3);
  Kernels k { MatX(m, 3), VecX(m) };
  for (int i = 0; i < m; ++i) {
    k.centres.row(i) << u(rng), u(rng), u(rng);
    k.weights[i] = g(rng);
  }
  return k;
}

} // namespace

TEST(EnergyKernelCopies, EqualsTheWeightedSumOfEachCentresKernel) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.5, 1.7);
  for (const int m : { 1, 3, 7 }) // 6m copies: 6, 18, 42, the last packed step partial for 3, 7
    for (const double epsilon : { 0.0, 1e-3, 0.05 }) {
      const Kernels k = random_kernels(m, rng);
      const EnergyKernelCopies copies(k.centres, k.weights, epsilon);
      for (int trial = 0; trial < 5; ++trial) {
        const Vec3 s(u(rng), u(rng), u(rng));
        SCOPED_TRACE(
            testing::Message() << "m " << m << ", ε " << epsilon << ", σ " << s.transpose());
        Vec3 want = Vec3::Zero();
        Mat3 want_hessian = Mat3::Zero();
        for (int i = 0; i < m; ++i) {
          Mat3 h;
          want += k.weights[i]
              * energy_kernel_gradient(s, k.centres.row(i).transpose(), epsilon, &h);
          want_hessian += k.weights[i] * h;
        }
        Mat3 hessian = Mat3::Identity(); // the sum is added to what is there
        const Vec3 got = copies.gradient_sum(s, &hessian);
        EXPECT_LE((got - want).norm(), 1e-12 * k.weights.norm());
        EXPECT_LE((hessian - Mat3::Identity() - want_hessian).norm(), 1e-11 * k.weights.norm());
        EXPECT_EQ(copies.gradient_sum(s, nullptr), got);
      }
    }
}

TEST(EnergyKernelCopies, TheAvxPathIsThePortablePathBitForBit) {
  if (!EnergyKernelCopies::uses_avx())
    GTEST_SKIP() << "no AVX on this machine: gradient_sum is the portable path";
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.3, 2.0);
  for (const int m : { 1, 2, 40 })
    for (const double epsilon : { 1e-3, 0.2 }) {
      const Kernels k = random_kernels(m, rng);
      const EnergyKernelCopies copies(k.centres, k.weights, epsilon);
      for (int trial = 0; trial < 100; ++trial) {
        const Vec3 s(u(rng), u(rng), u(rng));
        Mat3 fast = Mat3::Zero(), portable = Mat3::Zero();
        const Vec3 g_fast = copies.gradient_sum(s, &fast);
        const Vec3 g_portable = copies.gradient_sum_portable(s, &portable);
        ASSERT_EQ(g_fast, g_portable) << "m " << m << ", σ " << s.transpose();
        ASSERT_EQ(fast, portable) << "m " << m << ", σ " << s.transpose();
        ASSERT_EQ(copies.gradient_sum(s, nullptr), copies.gradient_sum_portable(s, nullptr));
      }
    }
}

TEST(EnergyKernelCopies, NoCentresSumToZero) {
  const EnergyKernelCopies copies(MatX(0, 3), VecX(0), 1e-3);
  Mat3 h = Mat3::Zero();
  EXPECT_TRUE(copies.empty());
  EXPECT_EQ(copies.gradient_sum(Vec3(1.1, 1, 0.9), &h), Vec3::Zero());
  EXPECT_EQ(h, Mat3::Zero());
}
