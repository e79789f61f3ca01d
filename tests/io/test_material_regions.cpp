// Heterogeneous scene materials ("material.regions"): a two-region bar stretches as two springs
// in series, layers select alternate slabs, and bad regions are errors naming the field.
#include "io_test_util.hpp"

#include <elastolearn/io/material_regions.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using Json = nlohmann::json;

namespace {

/// A 0.3 m bar along x, clamped at x = 0, its end x = 0.3 held displaced by `stretch` along x;
/// E = 1e5 Pa, ν = 0 (no lateral coupling), the part x > 0.1 stiffened by "regions".
Json stretched_bar(double stretch) {
  Json scene = Json::parse(R"({
    "format": "elastolearn-scene/1",
    "mesh": {"type": "box", "size": [0.3, 0.05, 0.05], "cells": [6, 2, 2]},
    "material": {"model": "corotated", "young": 1e5, "poisson": 0.0, "density": 1000,
                 "regions": [{"select": {"box": {"min": [0.1, -1, -1], "max": [1, 1, 1]}},
                              "young": 4e5}]},
    "fixed": [{"min": "x"}],
    "time": {"dt": 0.001, "frames": 1},
    "solver": {"newton_tolerance": 1e-13, "max_newton_iterations": 100}
  })");
  scene["keyframes"] = Json::array({ { { "select", { { "max", "x" } } },
      { "piecewise_linear",
          { { "times", { 0.0, 1.0 } },
              { "offsets", Json::array({ { stretch, 0, 0 }, { stretch, 0, 0 } }) } } } } });
  return scene;
}

SceneFile parse(const Json& json) {
  return parse_scene(json, "scene.json", std::filesystem::temp_directory_path());
}

} // namespace

TEST(MaterialRegions, TwoRegionBarStretchesAsSpringsInSeries) {
  // Corotated with ν = 0 under uniaxial stretch s has P₁₁ = E (s − 1) exactly, at any s, and no
  // lateral stress; linear tets represent each region's uniform stretch exactly. So the static
  // state is two springs in series: E₁ e₁ = E₂ e₂ and L₁ e₁ + L₂ e₂ = δ, the interface x = L₁
  // moves by L₁ e₁ = δ / (1 + (L₂/L₁)(E₁/E₂)), and nothing moves sideways. With δ = 0.03 m (10 %)
  // the answer is nonlinear-exact; Newton to 1e-13 leaves ~1e-12 m.
  const double delta = 0.03, L1 = 0.1, L2 = 0.2, E1 = 1e5, E2 = 4e5;
  const SceneFile file = parse(stretched_bar(delta));
  const sim::Scene& scene = file.scene;
  ASSERT_TRUE(scene.material.stiffness_scale);
  sim::Simulator simulator(scene);
  const sim::NewtonReport report = simulator.solve_static(4);
  ASSERT_TRUE(report.converged) << report.message;
  const double interface = delta / (1 + (L2 / L1) * (E1 / E2));
  const VecX& x = simulator.positions();
  const Positions& rest = scene.mesh.rest_positions();
  int checked = 0;
  for (int v = 0; v < scene.mesh.num_vertices(); ++v) {
    const Vec3 X = rest.row(v).transpose();
    const Vec3 u = x.segment<3>(3 * v) - X;
    // Every vertex: x-displacement piecewise linear in X, zero sideways.
    const double expected = X.x() <= L1 ? interface * X.x() / L1
                                        : interface + (delta - interface) * (X.x() - L1) / L2;
    EXPECT_NEAR(u.x(), expected, 1e-10) << "vertex " << v << " at x = " << X.x();
    EXPECT_NEAR(u.y(), 0, 1e-10);
    EXPECT_NEAR(u.z(), 0, 1e-10);
    checked += std::abs(X.x() - L1) < 1e-12;
  }
  EXPECT_EQ(checked, 9); // the interface plane's 3 × 3 vertices were among them
  // The homogeneous bar would stretch uniformly: its interface would move δ L₁/(L₁ + L₂), half
  // as far (the soft part takes most of the stretch).
  EXPECT_NEAR(interface, 2 * delta * L1 / (L1 + L2), 1e-15);
}

TEST(MaterialRegions, LayersSelectAlternateSlabsAndLaterRegionsOverride) {
  Json scene = stretched_bar(0);
  // 6 cells of 0.05 m along x, 24 tets each (6 per cell × 2 × 2): layers of period 0.1 starting
  // at 0.05 pick cells 1, 3, 5; a later box region overrides cell 5.
  scene["material"]["regions"] = Json::parse(R"([
    {"select": {"layers": {"axis": "x", "period": 0.1, "start": 0.05, "thickness": 0.05}},
     "young": 1e7},
    {"select": {"box": {"min": [0.25, -1, -1], "max": [1, 1, 1]}}, "young": 5e4}])");
  const SceneFile file = parse(scene);
  const auto& scale = *file.scene.material.stiffness_scale;
  const auto& mesh = file.scene.mesh;
  for (int e = 0; e < mesh.num_tets(); ++e) {
    double cx = 0;
    for (int a = 0; a < 4; ++a)
      cx += mesh.rest_positions()(mesh.tets()(e, a), 0) / 4;
    const int cell = static_cast<int>(cx / 0.05);
    const double expected = cell == 5 ? 0.5 : cell % 2 == 1 ? 100.0 : 1.0;
    EXPECT_EQ(scale[e], expected) << "tet " << e << " in cell " << cell;
  }
}

TEST(MaterialRegions, BadRegionsAreErrorsNamingTheField) {
  const auto with_regions = [](const char* regions) {
    Json scene = stretched_bar(0);
    scene["material"]["regions"] = Json::parse(regions);
    return scene;
  };
  expect_input_error(
      [&] {
        parse(with_regions(R"([{"select": {"box": {"min": [5, 5, 5],
      "max": [6, 6, 6]}}, "young": 1e6}])"));
      },
      { "scene.json", "material.regions[0].select", "selects no element" });
  expect_input_error(
      [&] { parse(with_regions(R"([{"select": {"elements": [0]}, "young": -3}])")); },
      { "scene.json", "material.regions[0].young", "-3" });
  expect_input_error([&] { parse(with_regions("[]")); }, { "material.regions", "empty" });
  expect_input_error(
      [&] {
        parse(with_regions(R"([{"select": {"elements": [0]}, "young": 1e6, "poison": 0.3}])"));
      },
      { "material.regions[0]", "poison" });
  expect_input_error(
      [&] {
        parse(with_regions(R"([{"select": {"elements": [9999]},
      "young": 1e6}])"));
      },
      { "material.regions[0].select.elements", "9999" });
  expect_input_error(
      [&] {
        parse(with_regions(R"([{"select": {"layers": {"axis": "x",
      "period": 0.1, "thickness": 0.1}}, "young": 1e6}])"));
      },
      { "material.regions[0].select.layers.thickness" });
  expect_input_error(
      [&] {
        parse(with_regions(R"([{"select": {"plane": {"axis": "x",
      "value": 0.1}}, "young": 1e6}])"));
      },
      { "material.regions[0].select.plane.tolerance" });
  expect_input_error([&] { parse(with_regions(R"([{"select": {}, "young": 1e6}])")); },
      { "material.regions[0].select", "exactly one of" });
}

TEST(MaterialRegions, LearningRefusesAHeterogeneousScene) {
  // A correction is one material's: learning from a scene with regions would silently learn
  // against the wrong nominal (the learning's element states know one material).
  const test::ScratchDir dir;
  Json scene = stretched_bar(0);
  scene["keyframes"] = Json::array();
  write_json_file(dir / "scene.json", scene);
  expect_input_error(
      [&] {
        read_training_motion({ dir / "scene.json", dir / "missing.h5" });
      },
      { "scene.json", "material.regions", "homogeneous" });
}
