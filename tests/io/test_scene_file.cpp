// Scene files: mesh placement, selections that select nothing, and starting from a recorded
// state of a trajectory file (restarting a run from one of its own frames continues it).
#include "io_test_util.hpp"

#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/scene_output.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/placement.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;
using Json = nlohmann::json;

namespace {

/// A bar clamped at x = 0 whose far end is shaken (sinusoid keyframe), pushed sideways in the
/// middle by a load released at t = 0.05 s, under gravity: every time-dependent input is used.
Json bar_scene() {
  return Json::parse(R"({
    "format": "elastolearn-scene/1",
    "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [6, 2, 2]},
    "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000,
                 "damping": {"alpha0": 0.1, "alpha1": 0.001}},
    "gravity": [0, -9.81, 0],
    "fixed": [{"min": "x"}],
    "keyframes": [{"select": {"max": "x"}, "sinusoid": {"amplitude": [0, 0.01, 0], "frequency": 5}}],
    "loads": [{"select": {"plane": {"axis": "x", "value": 0.1}}, "force": [0, 0, 2],
               "release_time": 0.05}],
    "time": {"dt": 0.002, "frames": 40}
  })");
}

SceneFile parse(const Json& json, const std::filesystem::path& dir) {
  return parse_scene(json, "scene.json", dir);
}

/// Simulate `json` into `dir/name` and read the trajectory back.
TrajectoryData simulate(const Json& json, const ScratchDir& dir, const std::string& name) {
  SceneOutputOptions options;
  options.trajectory = dir / name;
  const auto report = simulate_to_files(parse(json, dir.path()).scene, options, {});
  EXPECT_TRUE(report.completed) << report.message;
  return read_trajectory_h5(dir / name);
}

double max_distance(const Positions& a, const Positions& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

} // namespace

// --- mesh placement ---------------------------------------------------------------------------

TEST(SceneFile, KeepsAnInlineMaterialAsTheNominalMaterial) {
  const Json json = bar_scene();
  const SceneFile s = parse(json, std::filesystem::current_path());
  EXPECT_EQ(s.nominal_material, json.at("material"));
  EXPECT_FALSE(s.material_training_stretches.has_value());
}

TEST(SceneFile, PlacesTheMeshScaledThenRotatedThenTranslated) {
  ScratchDir dir;
  Json j = bar_scene();
  j.erase("keyframes"); // their selections would miss the moved bar
  j.erase("loads");
  j["mesh"]["scale"] = 2;
  j["mesh"]["rotate_deg"] = { 10, 20, 30 };
  j["mesh"]["translate"] = { 1, 2, 3 };
  const SceneFile s = parse(j, dir.path());
  mesh::Placement p;
  p.scale = 2;
  p.rotate_deg = Vec3(10, 20, 30);
  p.translate = Vec3(1, 2, 3);
  const mesh::TetMesh expected
      = mesh::place(mesh::make_box_bar(Vec3(0.2, 0.05, 0.05), { 6, 2, 2 }), p);
  EXPECT_EQ(s.scene.mesh.rest_positions(), expected.rest_positions()); // same arithmetic
  EXPECT_EQ(s.scene.mesh.tets(), expected.tets());

  // A mesh file is placed too (the two tets of the fixture; volume × s³).
  Json unscaled_json = bar_scene();
  unscaled_json["mesh"]
      = { { "file", std::string(ELASTOLEARN_TEST_DATA_DIR) + "/mesh/two_tets.node" } };
  unscaled_json.erase("keyframes");
  unscaled_json.erase("loads");
  Json scaled_json = unscaled_json;
  scaled_json["mesh"]["scale"] = 3;
  const SceneFile unscaled = parse(unscaled_json, dir.path());
  const SceneFile scaled = parse(scaled_json, dir.path());
  EXPECT_NEAR(scaled.scene.mesh.total_volume(), 27 * unscaled.scene.mesh.total_volume(),
      1e-12 * scaled.scene.mesh.total_volume());
}

TEST(SceneFile, RefusesANonPositiveScaleNamingTheField) {
  ScratchDir dir;
  for (double s : { -1.0, 0.0 }) {
    Json j = bar_scene();
    j["mesh"]["scale"] = s;
    expect_input_error(
        [&] { parse(j, dir.path()); }, { "scene.json: mesh.scale: must be positive" });
  }
  Json j = bar_scene();
  j["mesh"]["rotate_deg"] = { 90, 0 };
  expect_input_error([&] { parse(j, dir.path()); }, { "scene.json: mesh.rotate_deg" });
}

TEST(SceneFile, SolverStepHalvingsAreReadAndOutOfRangeIsAnErrorNamingTheField) {
  ScratchDir dir;
  EXPECT_EQ(parse(bar_scene(), dir.path()).scene.newton.max_step_halvings, 3);
  Json j = bar_scene();
  j["solver"] = { { "max_step_halvings", 0 } };
  EXPECT_EQ(parse(j, dir.path()).scene.newton.max_step_halvings, 0);
  for (int bad : { -1, 11 }) {
    j["solver"]["max_step_halvings"] = bad;
    expect_input_error([&] { parse(j, dir.path()); },
        { "scene.json: solver.max_step_halvings: must be in [0, 10]" });
  }
}

TEST(SceneFile, SolverStallIterationsAreReadAndANegativeCountIsAnErrorNamingTheField) {
  ScratchDir dir;
  EXPECT_EQ(parse(bar_scene(), dir.path()).scene.newton.stall_iterations, 20);
  Json j = bar_scene();
  j["solver"] = { { "stall_iterations", 0 } };
  EXPECT_EQ(parse(j, dir.path()).scene.newton.stall_iterations, 0);
  j["solver"]["stall_iterations"] = -1;
  expect_input_error([&] { parse(j, dir.path()); },
      { "scene.json: solver.stall_iterations: must be ≥ 0 (0: off)" });
}

TEST(SceneFile, SolverExtrapolateVelocityIsReadAndANonBooleanIsAnErrorNamingTheField) {
  ScratchDir dir;
  EXPECT_FALSE(parse(bar_scene(), dir.path()).scene.newton.extrapolate_velocity);
  Json j = bar_scene();
  j["solver"] = { { "extrapolate_velocity", true } };
  EXPECT_TRUE(parse(j, dir.path()).scene.newton.extrapolate_velocity);
  j["solver"]["extrapolate_velocity"] = 1;
  expect_input_error([&] { parse(j, dir.path()); }, { "scene.json: solver.extrapolate_velocity" });
}

// --- selections -------------------------------------------------------------------------------

TEST(SceneFile, EverySelectionThatSelectsNoVertexIsAnErrorNamingIt) {
  ScratchDir dir;
  const Json miss = Json::parse(R"({"box": {"min": [5, 5, 5], "max": [6, 6, 6]}})");
  const auto expect_empty = [&](Json j, const std::string& field) {
    expect_input_error(
        [&] { parse(j, dir.path()); }, { "scene.json: " + field + ": selects no vertex" });
  };
  Json j = bar_scene();
  j["fixed"] = Json::array({ Json::parse(R"({"min": "x"})"), miss });
  expect_empty(j, "fixed[1]");

  j = bar_scene();
  j["fixed"][0] = Json::parse(R"({"vertices": []})");
  expect_empty(j, "fixed[0]");

  j = bar_scene();
  j["fixed"][0] = Json::parse(R"({"plane": {"axis": "y", "value": 0.3}})");
  expect_empty(j, "fixed[0]");

  j = bar_scene();
  j["keyframes"][0]["select"] = miss;
  expect_empty(j, "keyframes[0].select");

  j = bar_scene();
  j["loads"][0]["select"] = miss;
  expect_empty(j, "loads[0].select");

  j = bar_scene();
  j["initial"] = { { "type", "static" },
    { "loads",
        Json::array({ { { "select", Json::parse(R"({"max": "x"})") }, { "force", { 0, 1, 0 } } },
            { { "select", miss }, { "force", { 0, 1, 0 } } } }) } };
  expect_empty(j, "initial.loads[1].select");
}

// --- starting from a recorded state -----------------------------------------------------------

TEST(SceneFile, RestartFromAFrameOfItsOwnOutputContinuesTheRun) {
  // The restart starts from frame k's positions and velocities at frame k's time, so it runs
  // the same steps as the original (same keyframe phase, same load release); the only
  // difference is the step times, t_k + j·dt instead of (k + j)·dt, which differ by round-off
  // (~1e-17 s). The states then agree to round-off, far inside 1e-9 m (the bar moves ~1e-2 m).
  // The consistent mass couples the keyframed vertices' velocities into the free rows, so it
  // also checks that those are taken from the file.
  for (const char* mass : { "lumped", "consistent" }) {
    SCOPED_TRACE(mass);
    ScratchDir dir;
    Json original = bar_scene();
    original["mass"] = mass;
    const TrajectoryData full = simulate(original, dir, "full.h5");
    ASSERT_EQ(full.positions.size(), 41u);
    ASSERT_FALSE(full.velocities.empty()) << "simulate records velocities";
    ASSERT_GT(max_distance(full.positions[15], full.positions[30]), 1e-3) << "it moves";

    const int k = 15;
    Json restart = original;
    restart["initial"] = { { "type", "trajectory" }, { "file", "full.h5" }, { "frame", k } };
    restart["time"]["frames"] = 40 - k;
    const TrajectoryData continued = simulate(restart, dir, "continued.h5");
    ASSERT_EQ(continued.positions.size(), size_t(40 - k + 1));
    for (size_t j = 0; j < continued.positions.size(); ++j) {
      EXPECT_NEAR(continued.time[j], full.time[k + j], 1e-12) << "frame " << j;
      EXPECT_LT(max_distance(continued.positions[j], full.positions[k + j]), 1e-9) << "frame " << j;
    }

    // A negative frame counts from the end.
    restart["initial"]["frame"] = -26;
    EXPECT_EQ(parse(restart, dir.path()).scene.initial.time, full.time[k]);
  }
}

TEST(SceneFile, RecordedStateKeepsPrescribedVerticesAndZeroesMissingVelocities) {
  ScratchDir dir;
  TrajectoryData full = simulate(bar_scene(), dir, "full.h5");
  full.velocities.clear();
  write_trajectory_h5(dir / "no_velocities.h5", full);

  Json j = bar_scene();
  j["initial"] = { { "type", "trajectory" }, { "file", "no_velocities.h5" }, { "frame", 10 } };
  const SceneFile s = parse(j, dir.path());
  EXPECT_EQ(s.scene.initial.velocities.rows(), 0);
  sim::Simulator simulator(s.scene);
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  EXPECT_EQ(simulator.time(), full.time[10]);
  EXPECT_EQ(simulator.velocities().norm(), 0.0);
  const VecX prescribed = simulator.prescribed_positions(full.time[10]);
  const VecX recorded = flatten(full.positions[10]);
  for (int v = 0; v < s.scene.mesh.num_vertices(); ++v) {
    const Vec3 expected = simulator.dofs().is_prescribed_vertex(v) ? prescribed.segment<3>(3 * v)
                                                                   : recorded.segment<3>(3 * v);
    EXPECT_EQ(Vec3(simulator.positions().segment<3>(3 * v)), expected) << "vertex " << v;
  }
}

TEST(SceneFile, RecordedStateErrorsNameTheField) {
  ScratchDir dir;
  simulate(bar_scene(), dir, "full.h5"); // 41 frames on the 6×2×2 bar
  const auto with_initial = [](Json initial) {
    Json j = bar_scene();
    j["initial"] = std::move(initial);
    return j;
  };
  const auto bad = [&](const Json& j, const std::vector<std::string>& parts) {
    expect_input_error([&] { parse(j, dir.path()); }, parts);
  };
  bad(with_initial({ { "type", "trajectory" }, { "file", "full.h5" }, { "frame", 41 } }),
      { "scene.json: initial.frame: 41 is out of range: full.h5 has 41 frames" });
  bad(with_initial({ { "type", "trajectory" }, { "file", "full.h5" }, { "frame", -42 } }),
      { "scene.json: initial.frame: -42 is out of range" });
  bad(with_initial({ { "type", "trajectory" }, { "file", "missing.h5" }, { "frame", 0 } }),
      { "scene.json: initial.file", "missing.h5" });
  bad(with_initial({ { "type", "trajectory" }, { "file", "full.h5" } }),
      { "scene.json: initial.frame: missing required field" });

  Json other_mesh
      = with_initial({ { "type", "trajectory" }, { "file", "full.h5" }, { "frame", 0 } });
  other_mesh["mesh"]["cells"] = { 6, 2, 1 };
  bad(other_mesh,
      { "scene.json: initial.file: full.h5 has 63 vertices but the scene mesh has 42" });

  Json moved = with_initial({ { "type", "trajectory" }, { "file", "full.h5" }, { "frame", 0 } });
  moved["mesh"]["translate"] = { 0, 0, 0.01 };
  bad(moved, { "scene.json: initial.file: full.h5 was recorded on another mesh or placement" });
}
