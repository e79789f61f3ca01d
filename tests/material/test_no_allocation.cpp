// The per-element material functions run inside parallel element loops and must not allocate
// (CONVENTIONS.md). malloc is interposed (glibc) and counted while a guard is active.
#include "model_zoo.hpp"

#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/stretch_dependent_rayleigh.hpp>

#include <support/material_states.hpp>

#include <atomic>
#include <cstdlib>

#if defined(__SANITIZE_ADDRESS__)
#define ELASTOLEARN_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define ELASTOLEARN_COUNT_MALLOC 0
#endif
#endif
#if !defined(ELASTOLEARN_COUNT_MALLOC) && defined(__GLIBC__)
#define ELASTOLEARN_COUNT_MALLOC 1
#endif

#if ELASTOLEARN_COUNT_MALLOC
namespace {
std::atomic<bool> counting { false };
std::atomic<long> allocations { 0 };
} // namespace
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* malloc(std::size_t n) {
  if (counting.load(std::memory_order_relaxed))
    ++allocations;
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t m) {
  if (counting.load(std::memory_order_relaxed))
    ++allocations;
  return __libc_calloc(n, m);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (counting.load(std::memory_order_relaxed))
    ++allocations;
  return __libc_realloc(p, n);
}
#endif

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

TEST(NoAllocation, PerElementMaterialFunctionsDoNotAllocate) {
#if !ELASTOLEARN_COUNT_MALLOC
  GTEST_SKIP() << "malloc cannot be interposed in this build (sanitizer or non-glibc)";
#else
  std::vector<std::unique_ptr<ElasticModel>> models;
  models.push_back(CorotatedFactory::make());
  models.push_back(StVKFactory::make());
  models.push_back(NeoHookeanFactory::make());
  models.push_back(SplineTensionNeoFactory::make());
  models.push_back(SplineCompressionCorotatedFactory::make());
  const AnalyticCorrection correction({ 2e5, 50.0, 3.0 });
  const StretchDependentRayleigh damping(
      CubicSpline({ 1.0 }, { 0.1 }), CubicSpline({ 1.0, 1.2, 1.6 }, { 0.01, 0.03, 0.05 }));
  const auto states = material_states();
  const Mat3 F_rate = rotated_stretch(Vec3(0.3, -0.2, 0.1), 77);
  // Sanity: the counter works.
  counting = true;
  void* volatile probe = std::malloc(16);
  counting = false;
  std::free(probe);
  ASSERT_EQ(allocations.load(), 1);
  allocations = 0;

  double sink = 0;
  counting = true;
  for (const auto& model : models) {
    for (const auto& state : states) {
      const PrincipalFrame frame = principal_frame(state.F);
      const Vec3 rates = stretch_rates(frame, F_rate);
      const CorrectedStress cs
          = corrected_principal_stress(*model, &correction, frame.stretches, rates);
      const Mat3 P = first_piola(frame, cs.stress);
      const Mat9 D = first_piola_derivative(frame, cs.stress, cs.d_stretches, true);
      const Mat9 Dr = first_piola_rate_derivative(frame, cs.d_stretch_rates);
      sink += P.sum() + D.sum() + Dr.sum() + model->energy(frame.stretches)
          + damping.coefficients(frame.stretches[0]).alpha1;
    }
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_TRUE(std::isfinite(sink));
#endif
}
