// The elastic model name table, the factory and Lamé parameters.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/elastic_model_type.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace elastolearn;
using namespace elastolearn::material;

TEST(ElasticModelType, NamesRoundTrip) {
  for (ElasticModelType t : all_elastic_model_types) {
    EXPECT_EQ(elastic_model_type_from_string(to_string(t)), t);
  }
  EXPECT_EQ(to_string(ElasticModelType::NeoHookean), "neohookean");
}

TEST(ElasticModelType, UnknownNameListsTheValidOnes) {
  try {
    elastic_model_type_from_string("neo-hookean", "scene.json: material.model");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "scene.json: material.model");
    const std::string what = e.what();
    EXPECT_NE(what.find("'neo-hookean'"), std::string::npos) << what;
    EXPECT_NE(what.find("corotated, stvk, neohookean, spline_edited"), std::string::npos) << what;
  }
}

TEST(ElasticModelType, FactoryBuildsModelsNamedByTheTable) {
  const Lame lame { 1e4, 4e4 };
  for (ElasticModelType t :
      { ElasticModelType::Corotated, ElasticModelType::StVK, ElasticModelType::NeoHookean }) {
    const auto m = make_elastic_model(t, lame);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->name(), to_string(t));
    // Linear response at rest: P̂ ≈ (2μ + λ) ε along a uniaxial stretch with the others fixed.
    const double eps = 1e-6;
    EXPECT_NEAR(m->principal_stress(Vec3(1 + eps, 1, 1))[0], (2 * lame.mu + lame.lambda) * eps,
        1e-4 * (2 * lame.mu + lame.lambda) * eps);
  }
  EXPECT_THROW(make_elastic_model(ElasticModelType::SplineEdited, lame), InputError);
}

TEST(Lame, FromYoungPoisson) {
  const Lame l = Lame::from_young_poisson(1.2e5, 0.43);
  EXPECT_NEAR(l.mu, 1.2e5 / (2 * 1.43), 1e-9);
  EXPECT_NEAR(l.lambda, 1.2e5 * 0.43 / (1.43 * (1 - 0.86)), 1e-7);
  // E and ν are recovered: E = μ(3λ + 2μ)/(λ + μ), ν = λ / (2(λ + μ)).
  EXPECT_NEAR(l.mu * (3 * l.lambda + 2 * l.mu) / (l.lambda + l.mu), 1.2e5, 1e-7);
  EXPECT_NEAR(l.lambda / (2 * (l.lambda + l.mu)), 0.43, 1e-14);
}

TEST(Lame, RejectsInvalidYoungOrPoisson) {
  EXPECT_THROW(Lame::from_young_poisson(0.0, 0.3), InputError);
  EXPECT_THROW(Lame::from_young_poisson(-1e5, 0.3), InputError);
  EXPECT_THROW(Lame::from_young_poisson(std::nan(""), 0.3), InputError);
  EXPECT_THROW(Lame::from_young_poisson(1e5, 0.5), InputError);
  EXPECT_THROW(Lame::from_young_poisson(1e5, -1.0), InputError);
  EXPECT_THROW(Lame::from_young_poisson(1e5, INFINITY), InputError);
  try {
    Lame::from_young_poisson(1e5, 0.7);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "poisson");
    EXPECT_NE(std::string(e.what()).find("0.7"), std::string::npos);
  }
}
