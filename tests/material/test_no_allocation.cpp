// The per-element material functions run inside parallel element loops and must not allocate
// (CONVENTIONS.md). malloc is interposed (glibc) and counted while a guard is active.
#include "model_zoo.hpp"

#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/element_stress.hpp>
#include <elastolearn/material/nn_correction.hpp>
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
      // The element kernel as fem::ElasticForce runs it (rate-dependent N, damping, a scale).
      const ElementStress es
          = element_stress({ model.get(), &correction, &damping, 1.5 }, frame.stretches, rates);
      const PrincipalTangent Td = damping_tangent(frame, es.damped(), DampingTangent::FlipFree);
      const Mat3 Pe = element_first_piola(frame, es.corrected().stress, &Td, F_rate);
      sink += P.sum() + D.sum() + Dr.sum() + model->energy(frame.stretches)
          + damping.coefficients(frame.stretches[0]).alpha1 + Pe.sum();
    }
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_TRUE(std::isfinite(sink));
#endif
}

TEST(NoAllocation, LearnedCorrectionsDoNotAllocate) {
#if !ELASTOLEARN_COUNT_MALLOC
  GTEST_SKIP() << "malloc cannot be interposed in this build (sanitizer or non-glibc)";
#else
  // The RBF (energy and stress kernels, with damping; continued beyond trusted stretches) and the
  // network correction (energy and stress kind; the fixed-size kernels of 8-8 and the general loops
  // of 5-7), as the element loops call them: N with its gradients, and Δα₁.
  std::vector<std::shared_ptr<const Correction>> corrections;
  RbfCorrection::Parameters rbf;
  rbf.centres = RbfCorrection::Centres::Constant(5, 3, 1.0);
  rbf.centres(1, 0) = rbf.centres(2, 1) = 1.1;
  rbf.weights = VecX::LinSpaced(5, -1e3, 1e3);
  rbf.damping_weights = VecX::LinSpaced(5, -1e-3, 1e-3);
  for (bool energy : { false, true }) {
    rbf.energy_kernels = energy;
    corrections.push_back(std::make_shared<RbfCorrection>(rbf));
  }
  // Continued beyond [0.95, 1.05] with the bounded edge Hessian (the states below leave it).
  RbfCorrection::Parameters continued = rbf;
  continued.trusted = { 0.95, 1.05, Continuation::bounded_softening };
  continued.trusted.nominal_stiffness = 1e4 * (Mat3::Identity() + Mat3::Ones());
  corrections.push_back(std::make_shared<RbfCorrection>(continued));
  for (NnKind kind : { NnKind::Stress, NnKind::Energy })
    for (int width : { 8, 5 }) {
      NnCorrection::Parameters p;
      p.kind = kind;
      p.activation = kind == NnKind::Energy ? Activation::Squareplus : Activation::Elu;
      const int inputs = kind == NnKind::Energy ? 3 : 6;
      p.input_mean = VecX::Zero(inputs);
      p.input_scale = VecX::Constant(inputs, 0.1);
      int in = inputs;
      for (int out : { width, width + 2, 1 }) {
        p.layers.push_back({ MatX::Constant(out, in, 0.3), VecX::Constant(out, 0.1) });
        in = out;
      }
      p.damping = std::make_shared<RbfCorrection>(damping_part(RbfCorrection(rbf)));
      corrections.push_back(std::make_shared<NnCorrection>(p));
    }
  allocations = 0;
  double sink = 0;
  counting = true;
  for (const auto& c : corrections) {
    for (const Vec3& s : { Vec3(1.1, 0.95, 0.9), Vec3(1.0, 1.0, 1.0), Vec3(1.3, 1.3, 0.6) }) {
      Mat3 ds, dr;
      sink += c->correction_with_gradient(s, Vec3(0.1, -0.2, 0.3), ds, dr).sum() + ds.sum()
          + dr.sum() + c->correction(s, Vec3::Zero()).sum() + c->stiffness_damping(s);
      c->correction_gradient(s, Vec3::Zero(), ds, dr);
      sink += ds.sum();
    }
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_TRUE(std::isfinite(sink));
#endif
}
