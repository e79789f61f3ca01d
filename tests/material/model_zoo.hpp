#pragma once
// The models every material test runs over, as GoogleTest types (one factory per model).
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/material/spline_edited.hpp>
#include <elastolearn/material/stvk.hpp>

#include <gtest/gtest.h>

#include <memory>

namespace elastolearn::test {

/// E = 100 kPa, ν = 0.4 (a soft, nearly incompressible solid like the paper's examples).
inline material::Lame test_lame() {
  return material::Lame::from_young_poisson(1e5, 0.4);
}

/// Tension edit: s rises from 1 at σ = 1.05 to 3 at σ = 1.9 (stiffens tension up to 3×).
inline material::CubicSpline tension_spline() {
  return material::CubicSpline({ 1.05, 1.25, 1.45, 1.9 }, { 1.0, 2.0, 2.7, 3.0 }, "tension_spline");
}
/// Compression edit for neo-Hookean: s falls to 0.2 (less of the positive f′ = μσ: stiffer).
inline material::CubicSpline compression_spline_neo() {
  return material::CubicSpline(
      { 0.3, 0.55, 0.85, 0.97 }, { 0.2, 0.35, 0.7, 1.0 }, "compression_spline");
}
/// Compression edit for corotated: s rises to 3 (f′ = 2μ(σ − 1) scaled up: stiffer).
inline material::CubicSpline compression_spline_corotated() {
  return material::CubicSpline(
      { 0.3, 0.55, 0.85, 0.97 }, { 3.0, 2.6, 1.7, 1.0 }, "compression_spline");
}

struct CorotatedFactory {
  static std::unique_ptr<material::ElasticModel> make() {
    return std::make_unique<material::CorotatedModel>(test_lame());
  }
};
struct StVKFactory {
  static std::unique_ptr<material::ElasticModel> make() {
    return std::make_unique<material::StVKModel>(test_lame());
  }
};
struct NeoHookeanFactory {
  static std::unique_ptr<material::ElasticModel> make() {
    return std::make_unique<material::NeoHookeanModel>(test_lame());
  }
};
struct SplineTensionNeoFactory {
  static std::unique_ptr<material::ElasticModel> make() {
    return std::make_unique<material::SplineEditedModel>(material::ElasticModelType::NeoHookean,
        test_lame(), material::SplineEditRegion::Tension, tension_spline());
  }
};
struct SplineCompressionNeoFactory {
  static std::unique_ptr<material::ElasticModel> make() {
    return std::make_unique<material::SplineEditedModel>(material::ElasticModelType::NeoHookean,
        test_lame(), material::SplineEditRegion::Compression, compression_spline_neo());
  }
};
struct SplineCompressionCorotatedFactory {
  static std::unique_ptr<material::ElasticModel> make() {
    return std::make_unique<material::SplineEditedModel>(material::ElasticModelType::Corotated,
        test_lame(), material::SplineEditRegion::Compression, compression_spline_corotated());
  }
};

using AllModelFactories = ::testing::Types<CorotatedFactory, StVKFactory, NeoHookeanFactory,
    SplineTensionNeoFactory, SplineCompressionNeoFactory, SplineCompressionCorotatedFactory>;

} // namespace elastolearn::test
