// The element kernel (material::element_stress): the corrected stress is s P̂ + N, the nominal α₁
// damps the corrected elastic stress at zero rate, a learned Δα₁ damps the nominal stress (so
// that where N = 0 it is exactly a change of α₁) and is clamped at α₁ + Δα₁ ≥ 0, and the
// correction's share of the damping is the damping with it minus without it.
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/element_stress.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>

#include <support/damped_analytic_correction.hpp>
#include <support/material_states.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::material;

namespace {

const CorotatedModel kNominal(Lame::from_young_poisson(5e4, 0.4));

using TestCorrection = test::DampedAnalyticCorrection;

const Vec3 kStretches(1.2, 0.95, 0.8), kRates(0.4, -0.3, 0.1);

double distance(const StressPair& a, const StressPair& b) {
  return (a.stress - b.stress).norm() + (a.d_stretches - b.d_stretches).norm();
}
double size(const StressPair& a) {
  return a.stress.norm() + a.d_stretches.norm();
}

} // namespace

TEST(ElementStress, CorrectedStressIsTheScaledNominalPlusTheCorrection) {
  const TestCorrection n({ 2e5, 50.0, 3.0 }, 0.0, 0.0);
  const CorrectedStress reference = corrected_principal_stress(kNominal, &n, kStretches, kRates);
  // Same arithmetic in the same order: identical.
  const CorrectedStress unscaled
      = element_stress({ &kNominal, &n, nullptr, 1.0 }, kStretches, kRates).corrected();
  EXPECT_EQ(unscaled.stress, reference.stress);
  EXPECT_EQ(unscaled.d_stretches, reference.d_stretches);
  EXPECT_EQ(unscaled.d_stretch_rates, reference.d_stretch_rates);
  // The stiffness scale multiplies the nominal stress and its derivative, not N.
  const ElementStress scaled = element_stress({ &kNominal, &n, nullptr, 2.5 }, kStretches, kRates);
  const Vec3 P = kNominal.principal_stress(kStretches);
  const Mat3 dP = kNominal.principal_stress_derivative(kStretches);
  EXPECT_LE((scaled.corrected().stress - (2.5 * P + n.correction(kStretches, kRates))).norm(),
      1e-12 * P.norm());
  EXPECT_LE((scaled.nominal.d_stretches - 2.5 * dP).norm(), 1e-12 * dP.norm());
  EXPECT_EQ(scaled.correction_d_rates, reference.d_stretch_rates);
}

TEST(ElementStress, Alpha1DampsTheCorrectedElasticStressAtZeroRate) {
  // A rate-dependent N: the corrected stress takes N(σ, ḟ), the stiffness α₁ damps is that of
  // s P̂ + N(σ, 0).
  const RayleighDamping rayleigh(0.3, 0.02);
  const TestCorrection n({ 2e5, 2e3, 3.0 }, 0.0, 0.0);
  const double s = 1.7;
  const ElementStress e = element_stress({ &kNominal, &n, &rayleigh, s }, kStretches, kRates);
  EXPECT_EQ(e.alpha.alpha0, 0.3);
  EXPECT_EQ(e.alpha.alpha1, 0.02);
  EXPECT_EQ(e.alpha1_change, 0.0);
  ASSERT_TRUE(e.has_damping());
  Mat3 dn, unused;
  const Vec3 n0 = n.correction(kStretches, Vec3::Zero());
  n.correction_gradient(kStretches, Vec3::Zero(), dn, unused);
  ASSERT_GT((n0 - n.correction(kStretches, kRates)).norm(), 0.1 * n0.norm()); // rates matter
  const StressPair expected { 0.02 * (s * kNominal.principal_stress(kStretches) + n0),
    0.02 * (s * kNominal.principal_stress_derivative(kStretches) + dn) };
  EXPECT_LE(distance(e.damped(), expected), 1e-12 * size(expected));
  // The correction's share is the damping with the correction minus without it.
  const ElementStress without
      = element_stress({ &kNominal, nullptr, &rayleigh, s }, kStretches, kRates);
  EXPECT_EQ(without.alpha1_change, 0.0);
  const StressPair difference { e.damped().stress - without.damped().stress,
    e.damped().d_stretches - without.damped().d_stretches };
  EXPECT_LE(distance(e.damped_by_correction(), difference), 1e-12 * size(expected));
  const StressPair alpha1_n0 { 0.02 * n0, 0.02 * dn };
  EXPECT_LE(distance(e.damped_by_correction(), alpha1_n0), 1e-12 * size(expected));
}

TEST(ElementStress, DeltaAlpha1IsAChangeOfAlpha1WhereTheCorrectionIsZero) {
  // With N ≡ 0, a Δα₁ = δ gives the damping of the nominal material with α₁ + δ, on the scaled
  // stiffness; a Δα₁ below −α₁ is clamped so the stiffness damping vanishes (never negative).
  const TestCorrection delta_only({ 0.0, 0.0, 0.0 }, 0.0, 0.0);
  const double s = 0.6, alpha1 = 0.02;
  const RayleighDamping rayleigh(0.3, alpha1);
  for (const double delta : { 0.015, -0.012 }) {
    SCOPED_TRACE(delta);
    const TestCorrection n({ 0.0, 0.0, 0.0 }, delta, 0.0);
    const ElementStress e = element_stress({ &kNominal, &n, &rayleigh, s }, kStretches, kRates);
    const RayleighDamping changed(0.3, alpha1 + delta);
    const ElementStress reference
        = element_stress({ &kNominal, nullptr, &changed, s }, kStretches, kRates);
    EXPECT_NEAR(e.alpha1_change, delta, 1e-17);
    EXPECT_LE(distance(e.damped(), reference.damped()), 1e-14 * size(reference.damped()));
    // What a unit Δα₁ damps is the scaled nominal stress.
    EXPECT_LE(distance(e.damped_per_alpha1_change(), e.nominal), 0.0);
  }
  const TestCorrection too_negative({ 0.0, 0.0, 0.0 }, -0.05, 0.0);
  const ElementStress clamped
      = element_stress({ &kNominal, &too_negative, &rayleigh, s }, kStretches, kRates);
  EXPECT_EQ(clamped.alpha1_change, -alpha1);
  EXPECT_TRUE(clamped.has_damping());
  EXPECT_LE(size(clamped.damped()), 1e-15 * s * size(clamped.nominal));
  // A stretch-dependent Δα₁ is evaluated at the element's stretches.
  const TestCorrection sloped({ 0.0, 0.0, 0.0 }, 0.001, 0.05);
  EXPECT_NEAR(
      element_stress({ &kNominal, &sloped, &rayleigh, s }, kStretches, kRates).alpha1_change,
      0.001 + 0.05 * (kStretches[0] - 1), 1e-17);
}

TEST(ElementStress, DeltaAlpha1DampsTheScaledNominalStressNotTheCorrection) {
  // α₁ (s P̂ + N(σ, 0)) + Δα₁ s P̂ (paper Eq. 13 as docs/learning.md "Damping part" states it):
  // a Δα₁ on the corrected stress would add Δα₁ N(σ, 0), about 2.5 % of the damped stress here,
  // 10 orders of magnitude above the tolerance.
  const RayleighDamping rayleigh(0.3, 0.02);
  const TestCorrection n({ 2e5, 2e3, 3.0 }, 0.01, 0.0);
  const double s = 1.7;
  const ElementStress e = element_stress({ &kNominal, &n, &rayleigh, s }, kStretches, kRates);
  EXPECT_NEAR(e.alpha1_change, 0.01, 1e-17);
  Mat3 dn, unused;
  const Vec3 n0 = n.correction(kStretches, Vec3::Zero());
  n.correction_gradient(kStretches, Vec3::Zero(), dn, unused);
  const Vec3 P = s * kNominal.principal_stress(kStretches);
  const Mat3 dP = s * kNominal.principal_stress_derivative(kStretches);
  const StressPair expected { 0.02 * (P + n0) + 0.01 * P, 0.02 * (dP + dn) + 0.01 * dP };
  EXPECT_LE(distance(e.damped(), expected), 1e-12 * size(expected));
  const StressPair share { 0.02 * n0 + 0.01 * P, 0.02 * dn + 0.01 * dP };
  EXPECT_LE(distance(e.damped_by_correction(), share), 1e-12 * size(expected));
  EXPECT_GT(0.01 * (n0.norm() + dn.norm()), 0.01 * size(expected));
}

TEST(ElementStress, NothingIsDampedWithoutDampingOrAStiffnessToScale) {
  // Neither a damping model nor a Δα₁: no stiffness damping.
  const TestCorrection n({ 2e5, 50.0, 3.0 }, 0.0, 0.0);
  EXPECT_FALSE(element_stress({ &kNominal, &n, nullptr, 1.0 }, kStretches, kRates).has_damping());
  EXPECT_FALSE(
      element_stress({ &kNominal, nullptr, nullptr, 1.0 }, kStretches, kRates).has_damping());
  // A Δα₁ alone (no damping model) damps the nominal stress with Δα₁⁺.
  const TestCorrection delta({ 0.0, 0.0, 0.0 }, 0.004, 0.0);
  const ElementStress alone
      = element_stress({ &kNominal, &delta, nullptr, 1.0 }, kStretches, kRates);
  EXPECT_EQ(alone.alpha1_change, 0.004);
  EXPECT_LE((alone.damped().stress - 0.004 * kNominal.principal_stress(kStretches)).norm(),
      1e-15 * alone.nominal.stress.norm());
  // No nominal model: N alone, a Δα₁ has nothing to scale.
  const ElementStress bare = element_stress({ nullptr, &delta, nullptr, 1.0 }, kStretches, kRates);
  EXPECT_EQ(bare.nominal.stress, Vec3::Zero());
  EXPECT_EQ(bare.alpha1_change, 0.0);
  EXPECT_FALSE(bare.has_damping());
}

TEST(ElementFirstPiola, IsTheStressPlusTheDampingTangentAlongTheStrainRate) {
  // P = U diag(p̂) Vᵀ + (dP_d/dF) vec(Ḟ) with the 9×9 of the same eigen-form tangent.
  const PrincipalFrame frame = principal_frame(test::rotated_stretch(Vec3(1.2, 0.95, 0.8), 5));
  const Mat3 F_rate = test::rotated_stretch(Vec3(0.3, -0.2, 0.1), 6);
  const Vec3 p = kNominal.principal_stress(frame.stretches);
  for (const DampingTangent kind : all_damping_tangents) {
    const PrincipalTangent t = damping_tangent(frame,
        StressPair { 0.02 * p, 0.02 * kNominal.principal_stress_derivative(frame.stretches) },
        kind);
    const Mat3 P = element_first_piola(frame, p, &t, F_rate);
    const Vec9 rate = first_piola_derivative(frame, t) * test::vec(F_rate);
    const Mat3 expected = first_piola(frame, p) + test::unvec(rate);
    EXPECT_LE((P - expected).norm(), 1e-12 * expected.norm());
    EXPECT_EQ(element_first_piola(frame, p, nullptr, F_rate), first_piola(frame, p));
    EXPECT_GT(test::unvec(rate).norm(), 1e-3 * expected.norm()); // the damping does contribute
  }
}
