// io::evaluate_material and io::truth_frames: evaluate's numbers and its checks of the truth.
#include "io_test_util.hpp"

#include <elastolearn/io/material_evaluation.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/scene_output.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/observe/visible_vertices.hpp>

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

TEST(MaterialEvaluation, AnObservationTruthMeasuresErrLOverItsSeenVertices) {
  // A truth given as observations (e.g. a fine motion seen at a coarse mesh's vertices): err_L is
  // the same statistic — the largest vertex distance over frames, in % of the size — over the
  // observed vertices only, and a lost entry is skipped whatever its stored position.
  const io::test::ScratchDir dir;
  const sim::Scene scene = small_scene();
  const io::TrajectoryData truth = simulated(scene, material_with_young(1.5e5));
  const std::vector<int> ids = { 3, 7, 8 };
  observe::Observation observed = observe::observe_vertices(truth.positions, scene.dt, ids, 0, 1);
  observed.valid = observe::ValidityMask::Ones(observed.num_frames(), 3);
  observed.valid(10, 1) = 0; // vertex 7 lost in the last frame ...
  observed.positions[10](1, 0) = std::nan(""); // ... where its position means nothing
  io::write_observation_h5(dir / "obs.h5", observed);
  const io::EvaluationTruth read = io::read_evaluation_truth(dir / "obs.h5", scene);
  ASSERT_TRUE(read.observed);
  EXPECT_EQ(read.num_frames(), 11);

  const io::MaterialEvaluation e = io::evaluate_material(
      scene, material_with_young(1.5e5), "truth.json", read, io::EvaluationOptions {});
  ASSERT_TRUE(e.completed());
  EXPECT_EQ(e.learned.error.max, 0.0);
  EXPECT_EQ(e.truth_vertices, 3);
  double largest = 0;
  long samples = 0;
  const io::TrajectoryData nominal = simulated(scene, material_with_young(1e5));
  for (int f = 0; f <= 10; ++f)
    for (int j = 0; j < 3; ++j) {
      if (f == 10 && j == 1)
        continue;
      largest = std::max(
          largest, (nominal.positions[f].row(ids[j]) - truth.positions[f].row(ids[j])).norm());
      ++samples;
    }
  EXPECT_GT(largest, 1e-5);
  EXPECT_EQ(e.nominal.error.max, largest);
  EXPECT_EQ(e.nominal.error.samples, samples);
  EXPECT_NEAR(e.nominal.percent.max, 100 * largest / e.size, 1e-12 * e.nominal.percent.max);
  const Json report = io::evaluation_to_json(e, scene, "bar.json", "truth.json", "obs.h5");
  EXPECT_EQ(report.at("truth_vertices"), 3);

  // A trajectory file is still read as one (every vertex).
  io::write_trajectory_h5(dir / "truth.h5", truth);
  const io::EvaluationTruth all = io::read_evaluation_truth(dir / "truth.h5", scene);
  EXPECT_FALSE(all.observed);
  EXPECT_EQ(all.frames.size(), 11u);
}

TEST(MaterialEvaluation, AnObservationTruthOfAnotherSceneIsRefusedNamingTheFile) {
  const io::test::ScratchDir dir;
  const sim::Scene scene = small_scene();
  const io::TrajectoryData truth = simulated(scene, material_with_young(1e5));
  std::vector<Positions> frames = truth.positions;
  frames.pop_back();
  io::write_observation_h5(
      dir / "short.h5", observe::observe_vertices(frames, scene.dt, { 1 }, 0, 1));
  io::test::expect_input_error(
      [&] { io::read_evaluation_truth(dir / "short.h5", scene); }, { "short.h5", "10", "11" });
  io::write_observation_h5(dir / "ids.h5",
      observe::observe_vertices(
          std::vector<Positions>(11, Positions::Zero(40, 3)), scene.dt, { 39 }, 0, 1));
  io::test::expect_input_error(
      [&] { io::read_evaluation_truth(dir / "ids.h5", scene); }, { "ids.h5", "39" });
}

} // namespace
