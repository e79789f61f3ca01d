// End-to-end tests of scene inputs through the CLI: `tetrahedralize --scale`, and `simulate`
// restarted from the last frame of an earlier run.
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/read_tet_mesh.hpp>
#include <elastolearn/mesh/tetrahedralize.hpp>

#include <filesystem>
#include <support/cli_runner.hpp>

#include <gtest/gtest.h>
#include <string>

namespace fs = std::filesystem;
using namespace elastolearn;

namespace {

using elastolearn::test::run;
using CliSceneTest = elastolearn::test::CliTestFolder;

/// A 1000 mm cube centred at the origin, outward-oriented triangles.
const char* k_millimetre_cube = R"(OFF
8 12 0
-500 -500 -500
 500 -500 -500
 500  500 -500
-500  500 -500
-500 -500  500
 500 -500  500
 500  500  500
-500  500  500
3 0 3 2
3 0 2 1
3 4 5 6
3 4 6 7
3 0 1 5
3 0 5 4
3 2 3 7
3 2 7 6
3 0 4 7
3 0 7 3
3 1 2 6
3 1 6 5
)";

} // namespace

TEST_F(CliSceneTest, TetrahedralizeScalesTheSurfaceBeforeMeshing) {
  if (!mesh::tetgen_available())
    GTEST_SKIP() << "TetGen program not found: " << mesh::tetgen_executable();
  const auto surface = write("cube_mm.off", k_millimetre_cube);
  const auto r = run(
      "tetrahedralize " + surface.string() + " --scale 0.001 -o " + (m_dir / "cube.node").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("scaled by 0.001"), std::string::npos) << r.output;
  const mesh::TetMesh cube = mesh::read_tet_mesh(m_dir / "cube.node");
  // TetGen keeps the input surface (-p): the mesh is the 1 m cube, up to the round-off of
  // scaling (500 · 0.001), of Steiner points on its faces and of summing the tet volumes.
  EXPECT_LT((cube.bounding_box().min() - Vec3::Constant(-0.5)).norm(), 1e-12);
  EXPECT_LT((cube.bounding_box().max() - Vec3::Constant(0.5)).norm(), 1e-12);
  EXPECT_NEAR(cube.total_volume(), 1.0, 1e-12);

  const auto bad = run(
      "tetrahedralize " + surface.string() + " --scale 0 -o " + (m_dir / "bad.node").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--scale: must be a positive number"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(m_dir / "bad.node"));
}

TEST_F(CliSceneTest, SimulateRestartsFromTheLastFrameOfATrajectory) {
  const std::string scene = R"({
    "format": "elastolearn-scene/1",
    "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [4, 1, 1]},
    "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000},
    "gravity": [0, -9.81, 0],
    "fixed": [{"min": "x"}],
    "time": {"dt": 0.002, "frames": 10})";
  const auto first = write("first.json", scene + "}");
  ASSERT_EQ(
      run("simulate " + first.string() + " -o " + (m_dir / "first.h5").string() + " -q").exit_code,
      0);
  const auto second = write("second.json",
      scene + R"(, "initial": {"type": "trajectory", "file": "first.h5", "frame": -1}})");
  const auto r
      = run("simulate " + second.string() + " -o " + (m_dir / "second.h5").string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto a = io::read_trajectory_h5(m_dir / "first.h5");
  const auto b = io::read_trajectory_h5(m_dir / "second.h5");
  // The second run starts where and when the first one ended.
  EXPECT_EQ(b.time.front(), a.time.back());
  EXPECT_EQ(b.positions.front(), a.positions.back());
  EXPECT_NEAR(b.time.back(), 0.04, 1e-12);
}
