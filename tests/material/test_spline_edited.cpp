// Spline-edited materials (Xu et al. 2015): the edit's strength, locality, energy and validation.
// Consistency (P = ∂Ψ/∂F, tangent) is covered by the typed battery in test_elastic_models.cpp.
#include "model_zoo.hpp"

#include <elastolearn/core/error.hpp>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

TEST(SplineEdited, TensionEditStiffensTensionStrongly) {
  const auto edited = SplineTensionNeoFactory::make();
  const NeoHookeanModel base(test_lame());
  const Vec3 s(1.5, 1.0, 1.0);
  // Stress doubles at least (s(1.5) ≈ 2.7 scales f′ = μσ, about half of the base stress).
  EXPECT_GT(edited->principal_stress(s)[0], 2.0 * base.principal_stress(s)[0]);
  // The uniaxial stiffness ∂P̂₁/∂σ₁ as well.
  EXPECT_GT(edited->principal_stress_derivative(s)(0, 0),
      1.5 * base.principal_stress_derivative(s)(0, 0));
}

TEST(SplineEdited, CompressionEditOnCorotatedStiffensCompression) {
  const auto edited = SplineCompressionCorotatedFactory::make();
  const CorotatedModel base(test_lame());
  const Vec3 s(0.6, 1.0, 1.0);
  EXPECT_LT(edited->principal_stress(s)[0], 1.4 * base.principal_stress(s)[0]); // both negative
}

TEST(SplineEdited, EditIsLocalToItsRegion) {
  const auto tension = SplineTensionNeoFactory::make();
  const auto compression = SplineCompressionNeoFactory::make();
  const NeoHookeanModel base(test_lame());
  // Below the first tension knot (1.05) and above the last compression knot (0.97) s ≡ 1.
  for (const Vec3& s : { Vec3(1.04, 0.8, 0.5), Vec3(1.0, 1.0, 1.0), Vec3(1.03, 0.6, -0.4) }) {
    EXPECT_EQ(tension->principal_stress(s), base.principal_stress(s));
    EXPECT_EQ(tension->energy(s), base.energy(s));
  }
  for (const Vec3& s : { Vec3(2.0, 1.5, 0.98), Vec3(1.3, 1.0, 1.0) }) {
    EXPECT_EQ(compression->principal_stress(s), base.principal_stress(s));
    EXPECT_EQ(compression->energy(s), base.energy(s));
  }
}

TEST(SplineEdited, EditEnergyIsTheIntegralOfTheEditedStress) {
  const SplineEditedModel m(
      ElasticModelType::NeoHookean, test_lame(), SplineEditRegion::Tension, tension_spline());
  EXPECT_EQ(m.edit_energy(1.0), 0.0);
  for (double x : { 1.1, 1.3, 1.77, 2.5 }) {
    // Independent check: composite Simpson with 20000 panels (error ~1e-14 of the integral
    // apart from the kinks of s″ at the knots, which cost O(h³) ≈ 1e-12).
    const int n = 20000;
    const double h = (x - 1) / n;
    double sum = 0;
    for (int k = 0; k <= n; ++k) {
      const double t = 1 + k * h;
      const double w = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
      sum += w * (m.spline().value(t) - 1) * m.f_prime(t);
    }
    sum *= h / 3;
    EXPECT_NEAR(m.edit_energy(x), sum, 1e-9 * std::abs(sum)) << "x = " << x;
  }
}

TEST(SplineEdited, RejectsInvalidEdits) {
  const Lame lame = test_lame();
  auto expect_error = [&](ElasticModelType base, SplineEditRegion region, CubicSpline spline,
                          const std::string& where, const std::string& needle) {
    try {
      SplineEditedModel m(base, lame, region, std::move(spline), "material");
      FAIL() << "expected InputError about " << needle;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), where);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(ElasticModelType::StVK, SplineEditRegion::Tension, tension_spline(), "material.base",
      "'stvk'");
  expect_error(ElasticModelType::NeoHookean, SplineEditRegion::Compression, tension_spline(),
      "material.spline", "x <= 1");
  expect_error(ElasticModelType::NeoHookean, SplineEditRegion::Tension,
      CubicSpline({ 0.9, 1.5 }, { 1.0, 2.0 }), "material.spline", "x >= 1");
  expect_error(ElasticModelType::NeoHookean, SplineEditRegion::Tension,
      CubicSpline({ 1.0, 1.5 }, { 1.2, 2.0 }), "material.spline", "must have value 1");
  expect_error(ElasticModelType::Corotated, SplineEditRegion::Compression,
      CubicSpline({ 0.5, 1.0 }, { -0.5, 1.0 }), "material.spline", "positive");
}

TEST(SplineEdited, RegionNamesRoundTrip) {
  for (SplineEditRegion r : { SplineEditRegion::Tension, SplineEditRegion::Compression }) {
    EXPECT_EQ(spline_edit_region_from_string(to_string(r)), r);
  }
  EXPECT_THROW(spline_edit_region_from_string("stretch"), InputError);
}

TEST(SplineEdited, CloneKeepsTheEdit) {
  const auto m = SplineTensionNeoFactory::make();
  const auto copy = m->clone();
  const auto& edited = dynamic_cast<const SplineEditedModel&>(*copy);
  EXPECT_EQ(edited.base_type(), ElasticModelType::NeoHookean);
  EXPECT_EQ(edited.region(), SplineEditRegion::Tension);
  EXPECT_EQ(copy->principal_stress(Vec3(1.5, 1.2, 0.9)), m->principal_stress(Vec3(1.5, 1.2, 0.9)));
}
