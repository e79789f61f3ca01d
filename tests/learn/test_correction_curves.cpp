// Correction curves for the report: the paths are what they say (sorted stretches, the stated
// deformation scale), a model's stress difference to itself is its correction, a truth's is its
// stress minus the nominal's, and the damping law adds Δα₁ to α₁ as the simulation does.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/correction_curves.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>

#include <gtest/gtest.h>

namespace elastolearn::learn {
namespace {

using namespace material;

/// Δα₁(σ) = k (σ₁ − 1): a damping correction with a known value.
class LinearDampingCorrection final : public Correction {
  public:
  explicit LinearDampingCorrection(double k)
      : m_k(k) { }
  std::string name() const override { return "linear damping"; }
  Vec3 correction(const Vec3&, const Vec3&) const override { return Vec3::Zero(); }
  void correction_gradient(const Vec3&, const Vec3&, Mat3& ds, Mat3& dr) const override {
    ds.setZero();
    dr.setZero();
  }
  double stiffness_damping(const Vec3& s) const override { return m_k * (s[0] - 1); }
  std::unique_ptr<Correction> clone() const override {
    return std::make_unique<LinearDampingCorrection>(m_k);
  }

  private:
  double m_k;
};

fem::MaterialModel corotated(double young) {
  fem::MaterialModel m;
  m.elastic = std::make_shared<CorotatedModel>(Lame::from_young_poisson(young, 0.4));
  m.damping = std::make_shared<RayleighDamping>(0.0, 0.01);
  return m;
}

TEST(CorrectionCurves, PathsHoldSortedStretchesAtTheirAbscissae) {
  const StretchPath u = uniaxial_path(0.8, 1.2, 5);
  ASSERT_EQ(u.x.size(), 5u);
  EXPECT_DOUBLE_EQ(u.x.front(), 0.8);
  EXPECT_DOUBLE_EQ(u.x.back(), 1.2);
  EXPECT_TRUE(u.stretches.front().isApprox(Vec3(1, 1, 0.8)));
  EXPECT_TRUE(u.stretches.back().isApprox(Vec3(1.2, 1, 1)));

  const auto paths = deformation_scale_paths(0.3, 7);
  ASSERT_EQ(paths.size(), 6u);
  for (const StretchPath& p : paths) {
    for (std::size_t i = 0; i < p.x.size(); ++i) {
      EXPECT_NEAR((p.stretches[i] - Vec3::Ones()).norm(), p.x[i], 1e-14) << p.label;
      EXPECT_GE(p.stretches[i][0], p.stretches[i][1]);
      EXPECT_GE(p.stretches[i][1], p.stretches[i][2]);
    }
  }

  const StretchPath l = largest_stretch_path(0.9, 1.1, 3);
  for (std::size_t i = 0; i < l.x.size(); ++i)
    EXPECT_DOUBLE_EQ(l.stretches[i][0], l.x[i]) << "the largest stretch is the abscissa";
  EXPECT_TRUE(l.stretches.front().isApprox(Vec3::Constant(0.9)));

  EXPECT_THROW(uniaxial_path(1.2, 0.8, 5), InputError);
  EXPECT_THROW(uniaxial_path(0.8, 1.2, 1), InputError);
  EXPECT_THROW(deformation_scale_paths(1.0, 5), InputError);
}

TEST(CorrectionCurves, StressDifferenceIsTheCorrectionOrTheTruthsExcess) {
  const StretchPath u = uniaxial_path(0.8, 1.2, 9);
  fem::MaterialModel learned = corotated(1e6);
  learned.correction
      = std::make_shared<AnalyticCorrection>(AnalyticCorrection::Parameters { 5e5, 7, 0 });
  const auto n = stress_difference(u, learned, *learned.elastic);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const Vec3 s = u.stretches[i];
    // N(σ, 0) of the analytic correction: a (σᵢ − 1)³; its rate term vanishes at rest rates.
    const Vec3 expected = 5e5 * (s.array() - 1).cube();
    EXPECT_LT((n[i] - expected).norm(), 1e-9 * (1 + expected.norm()));
  }
  fem::MaterialModel truth;
  truth.elastic = std::make_shared<NeoHookeanModel>(Lame::from_young_poisson(8e5, 0.4));
  const auto t = stress_difference(u, truth, *learned.elastic);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Vec3 expected = truth.elastic->principal_stress(u.stretches[i])
        - learned.elastic->principal_stress(u.stretches[i]);
    EXPECT_LT((t[i] - expected).norm(), 1e-9 * (1 + expected.norm()));
  }
  // Both models are stress-free at rest: so is their difference.
  const StretchPath rest = uniaxial_path(1 - 1e-12, 1 + 1e-12, 2);
  EXPECT_LT(stress_difference(rest, truth, *learned.elastic)[0].norm(), 1e-3);
}

TEST(CorrectionCurves, DampingLawAddsTheCorrectionClampedAtZero) {
  const StretchPath l = largest_stretch_path(0.5, 1.5, 11);
  fem::MaterialModel m = corotated(1e6);
  EXPECT_EQ(stiffness_damping(l, m), std::vector<double>(11, 0.01));
  m.correction = std::make_shared<LinearDampingCorrection>(0.04);
  const auto alpha = stiffness_damping(l, m);
  for (std::size_t i = 0; i < alpha.size(); ++i)
    EXPECT_NEAR(alpha[i], std::max(0.0, 0.01 + 0.04 * (l.x[i] - 1)), 1e-15) << l.x[i];
  EXPECT_EQ(alpha.front(), 0.0) << "α₁ + Δα₁ = 0.01 − 0.02 is clamped to 0";
}

TEST(CorrectionCurves, InsideFollowsTheTrainingRange) {
  const StretchPath u = uniaxial_path(0.8, 1.2, 5); // s = 0.8, 0.9, 1.0, 1.1, 1.2
  StretchRange range;
  range.include(Vec3(1.15, 1, 0.95));
  range.include(Vec3(1, 1, 1));
  EXPECT_EQ(inside(u, range), (std::vector<bool> { false, false, true, true, false }));
  EXPECT_EQ(inside(u, StretchRange {}), std::vector<bool>(5, false));
}

} // namespace
} // namespace elastolearn::learn
