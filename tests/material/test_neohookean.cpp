// Neo-Hookean specifics: the classical formula where it is defined and the inversion extension.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/neohookean.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace elastolearn;
using namespace elastolearn::material;

namespace {
const Lame lame { 3.0e4, 1.2e5 };
}

TEST(NeoHookean, MatchesTheClassicalFormulaAboveTheThreshold) {
  const NeoHookeanModel m(lame);
  const Vec3 s(1.4, 0.9, 0.35);
  const double J = s.prod(), lnJ = std::log(J);
  EXPECT_NEAR(m.energy(s),
      0.5 * lame.mu * (s.squaredNorm() - 3) - lame.mu * lnJ + 0.5 * lame.lambda * lnJ * lnJ,
      1e-10 * lame.lambda);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(m.principal_stress(s)[i], lame.mu * (s[i] - 1 / s[i]) + lame.lambda * lnJ / s[i],
        1e-10 * lame.lambda);
  }
}

TEST(NeoHookean, ExtensionIsTwiceContinuousAtTheThreshold) {
  const NeoHookeanModel m(lame, 0.2);
  const double d = 1e-9;
  double l0, dl0, ddl0, l1, dl1, ddl1;
  m.extended_log(0.2 - d, l0, dl0, ddl0);
  m.extended_log(0.2 + d, l1, dl1, ddl1);
  // Across ε the values move by 2d times the next derivative (ℓ′ = 5, ℓ″ = −25, |ℓ‴| ≤ 250 at
  // ε = 0.2), i.e. ≤ 5e-7; a jump in ℓ, ℓ′ or ℓ″ would be of order 1 to 25.
  EXPECT_NEAR(l0, l1, 1e-6);
  EXPECT_NEAR(dl0, dl1, 1e-6);
  EXPECT_NEAR(ddl0, ddl1, 1e-6);
  EXPECT_NEAR(l1, std::log(0.2), 1e-8);
  EXPECT_NEAR(ddl0, -25.0, 1e-12);
  // Below ε, ℓ′ keeps growing (ℓ″ = −1/ε² < 0) and stays positive: a restoring stress.
  m.extended_log(-1.0, l0, dl0, ddl0);
  EXPECT_GT(dl0, 5.0);
}

TEST(NeoHookean, StaysFiniteAndGrowsThroughInversion) {
  const NeoHookeanModel m(lame);
  double previous = m.energy(Vec3(1.1, 0.9, 0.3));
  for (double s3 = 0.25; s3 > -1.0; s3 -= 0.05) {
    const Vec3 s(1.1, 0.9, s3);
    const double e = m.energy(s);
    EXPECT_TRUE(std::isfinite(e));
    EXPECT_TRUE(m.principal_stress(s).allFinite());
    EXPECT_TRUE(m.principal_stress_derivative(s).allFinite());
    EXPECT_GT(e, previous) << "energy must keep growing as the element inverts, sigma3 = " << s3;
    previous = e;
  }
}

TEST(NeoHookean, RejectsInvalidThreshold) {
  EXPECT_THROW(NeoHookeanModel(lame, 0.0), InputError);
  EXPECT_THROW(NeoHookeanModel(lame, 1.0), InputError);
  EXPECT_THROW(NeoHookeanModel(lame, std::nan("")), InputError);
}
