// io::evaluate_material and io::truth_frames: evaluate's numbers and its checks of the truth.
#include "io_test_util.hpp"

#include <elastolearn/io/material_evaluation.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/scene_output.hpp>

#include <gtest/gtest.h>

namespace {

using namespace elastolearn;
using Json = nlohmann::json;

const Json k_material = { { "model", "corotated" }, { "young", 1e5 }, { "poisson", 0.3 },
  { "density", 1000 }, { "damping", { { "alpha0", 0.1 }, { "alpha1", 0.001 } } } };

sim::Scene small_scene() {
  const Json scene = { { "format", "elastolearn-scene/1" },
    { "mesh", { { "type", "box" }, { "size", { 0.2, 0.05, 0.05 } }, { "cells", { 4, 1, 1 } } } },
    { "material", k_material }, { "gravity", { 0, -9.81, 0 } },
    { "fixed", Json::array({ { { "min", "x" } } }) },
    { "time", { { "dt", 0.002 }, { "frames", 10 } } } };
  return io::parse_scene(scene, "bar.json", ".").scene;
}

io::MaterialFile material_with_young(double young) {
  io::MaterialFile file;
  file.material = k_material;
  file.material["young"] = young;
  return file;
}

/// The scene simulated with `material`, as a trajectory.
io::TrajectoryData simulated(sim::Scene scene, const io::MaterialFile& material) {
  scene.material = io::material_model(material, "truth");
  sim::SimulationReport report;
  io::TrajectoryData t = io::simulate_trajectory(scene, 1, {}, report);
  EXPECT_TRUE(report.completed) << report.message;
  return t;
}

TEST(MaterialEvaluation, TheTrueMaterialHasNoErrorAndTheNominalItsMaxDistance) {
  const sim::Scene scene = small_scene();
  const io::MaterialFile truth_material = material_with_young(1.5e5);
  const io::TrajectoryData truth = simulated(scene, truth_material);
  const std::vector<VecX> frames = io::truth_frames(truth, "truth.h5", scene);
  ASSERT_EQ(frames.size(), 11u);

  std::vector<std::string> started;
  io::EvaluationOptions options;
  options.started = [&](const io::MaterialEvaluation& e) {
    started = { e.nominal.description, e.learned.description };
  };
  const io::MaterialEvaluation e
      = io::evaluate_material(scene, truth_material, "truth.json", frames, options);
  EXPECT_EQ(
      started, (std::vector<std::string> { "corotated (the scene's)", "corotated (truth.json)" }));
  ASSERT_TRUE(e.completed());
  // Same simulator, same material: the learned run is the truth, bit for bit.
  EXPECT_EQ(e.learned.error.max, 0.0);
  EXPECT_FALSE(e.max_ratio().has_value());
  // err_L of the nominal: the largest vertex distance over all frames, in % of the size.
  double largest = 0;
  const io::TrajectoryData nominal = simulated(scene, material_with_young(1e5));
  for (size_t f = 0; f < frames.size(); ++f)
    largest = std::max(
        largest, (nominal.positions[f] - truth.positions[f]).rowwise().norm().maxCoeff());
  EXPECT_GT(largest, 1e-5);
  EXPECT_EQ(e.nominal.error.max, largest);
  EXPECT_NEAR(e.nominal.percent.max, 100 * largest / e.size, 1e-12 * e.nominal.percent.max);

  const Json report = io::evaluation_to_json(e, scene, "bar.json", "truth.json", "truth.h5");
  EXPECT_EQ(report.at("format"), "elastolearn-evaluation/1");
  EXPECT_EQ(report.at("frames"), 11);
  EXPECT_TRUE(report.at("improvement").at("err_L").is_null());
  EXPECT_EQ(report.at("nominal").at("max_error"), largest);
}

TEST(MaterialEvaluation, ATruthOfAnotherSceneIsRefusedNamingItsDataset) {
  const sim::Scene scene = small_scene();
  const io::TrajectoryData truth = simulated(scene, material_with_young(1e5));
  io::TrajectoryData t = truth;
  t.positions.pop_back();
  t.time.pop_back();
  io::test::expect_input_error(
      [&] { io::truth_frames(t, "t.h5", scene); }, { "t.h5: /positions", "10 frames", "11" });
  t = truth;
  for (double& time : t.time)
    time *= 2;
  io::test::expect_input_error([&] { io::truth_frames(t, "t.h5", scene); }, { "t.h5: /time" });
  t = truth;
  t.rest_positions(3, 1) += 1e-3;
  io::test::expect_input_error(
      [&] { io::truth_frames(t, "t.h5", scene); }, { "t.h5: /rest_positions", "differ" });
}

} // namespace
