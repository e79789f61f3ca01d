// The scene's "material.damping": constant, spline and polynomial coefficients of σ₁.
#include <elastolearn/io/scene_material.hpp>

#include "io_test_util.hpp"

#include <gtest/gtest.h>

using namespace elastolearn;
using Json = nlohmann::json;

namespace {

fem::MaterialModel material_with_damping(const Json& damping) {
  const Json m
      = { { "model", "corotated" }, { "young", 4e4 }, { "poisson", 0.43 }, { "damping", damping } };
  return io::parse_material(io::JsonObject(m, "scene.json", "material"));
}

} // namespace

TEST(SceneMaterial, DampingPolynomialIsInTheStretchBeyondRest) {
  // α₁(σ₁) = 0.2 + 13.833 (σ₁ − 1) − 16.67 (σ₁ − 1)², α₀ a plain number.
  const auto m = material_with_damping(
      { { "alpha0", 0.5 }, { "alpha1", { { "polynomial", { 0.2, 13.833, -16.67 } } } } });
  ASSERT_FALSE(m.damping->is_constant());
  for (double s : { 1.0, 1.03, 1.08, 1.12 }) {
    const double t = s - 1;
    EXPECT_NEAR(m.damping->coefficients(s).alpha1, 0.2 + 13.833 * t - 16.67 * t * t, 1e-14) << s;
    EXPECT_EQ(m.damping->coefficients(s).alpha0, 0.5);
  }
  // Below σ₁ ≈ 0.9856 the polynomial is negative: clamped, so the damping never adds energy.
  EXPECT_EQ(m.damping->coefficients(0.98).alpha1, 0.0);
}

TEST(SceneMaterial, DampingSplineStillReads) {
  const auto m = material_with_damping(
      { { "alpha1", { { "stretches", { 1.0, 1.1 } }, { "values", { 0.1, 0.3 } } } } });
  EXPECT_DOUBLE_EQ(m.damping->coefficients(1.1).alpha1, 0.3);
  EXPECT_DOUBLE_EQ(m.damping->coefficients(0.9).alpha1, 0.1);
  EXPECT_EQ(m.damping->coefficients(1.05).alpha0, 0.0);
}

TEST(SceneMaterial, BadDampingCurvesNameTheField) {
  io::test::expect_input_error(
      [] {
        material_with_damping({ { "alpha1", { { "polynomial", Json::array() } } } });
      },
      { "scene.json: material.damping.alpha1.polynomial", "at least one coefficient" });
  io::test::expect_input_error(
      [] {
        material_with_damping(
            { { "alpha1", { { "polynomial", { 0.2 } }, { "values", { 0.1 } } } } });
      },
      { "material.damping.alpha1.polynomial", "not both" });
  io::test::expect_input_error(
      [] {
        material_with_damping({ { "alpha1", { { "polynomial", { 0.2, "x" } } } } });
      },
      { "material.damping.alpha1.polynomial[1]" });
  io::test::expect_input_error(
      [] {
        material_with_damping({ { "alpha1", { { "polynomal", { 0.2 } } } } });
      },
      { "polynomal", "polynomial" });
  io::test::expect_input_error(
      [] {
        material_with_damping(
            { { "alpha1", { { "stretches", { 1.0, 1.1 } }, { "values", { 0.1, -0.3 } } } } });
      },
      { "material.damping.alpha1", "non-negative" });
}
