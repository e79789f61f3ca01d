// io::observe_trajectory: what observe writes, and the errors that name the trajectory or the
// vertex list.
#include "io_test_util.hpp"

#include <elastolearn/io/trajectory_observation.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <gtest/gtest.h>

namespace {

using namespace elastolearn;

/// A box bar's rest shape moved rigidly by 1 mm per frame along x (3 frames, 10 ms apart).
io::TrajectoryData moving_bar() {
  const mesh::TetMesh mesh = mesh::make_box_bar(Vec3(0.2, 0.05, 0.05), { 4, 1, 1 });
  io::TrajectoryData t;
  t.rest_positions = mesh.rest_positions();
  t.tets = mesh.tets();
  for (int f = 0; f < 3; ++f) {
    Positions x = mesh.rest_positions();
    x.col(0).array() += 1e-3 * f;
    t.positions.push_back(x);
    t.time.push_back(0.5 + 0.01 * f);
  }
  return t;
}

TEST(TrajectoryObservation, ObservesTheGivenVerticesExactlyWithTheirMetadata) {
  const io::TrajectoryData t = moving_bar();
  io::ObservationRequest request;
  request.vertices = std::vector<int> { 7, 2 };
  request.vertices_source = "ids.txt";
  const io::TrajectoryObservation o = io::observe_trajectory(t, "bar.h5", request);
  ASSERT_EQ(o.observation.num_frames(), 3);
  EXPECT_EQ(o.observation.vertex_ids, (std::vector<int> { 7, 2 }));
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(o.observation.positions[f].row(0), t.positions[f].row(7));
    EXPECT_EQ(o.observation.positions[f].row(1), t.positions[f].row(2));
  }
  EXPECT_NEAR(o.observation.dt, 0.01, 1e-15);
  EXPECT_EQ(o.observation.start_time, 0.5);
  EXPECT_EQ(o.metadata.at("source"), "bar.h5");
  EXPECT_EQ(o.metadata.at("selection"), "vertex list ids.txt");
  EXPECT_EQ(o.metadata.at("noise_sigma"), "0");
  // A 4 × 1 × 1 box: all 20 vertices are on the surface.
  EXPECT_EQ(o.surface_vertices, 20);
  EXPECT_NEAR(o.size, Vec3(0.2, 0.05, 0.05).norm(), 1e-15);
}

TEST(TrajectoryObservation, AFractionSpreadsOverTheSurface) {
  io::ObservationRequest request;
  request.visible_fraction = 0.5;
  request.seed = 3;
  const io::TrajectoryObservation o = io::observe_trajectory(moving_bar(), "bar.h5", request);
  EXPECT_EQ(o.observation.num_observed(), 10);
  EXPECT_EQ(o.metadata.at("selection"), "visible fraction 0.5 (farthest-point sampling)");
  EXPECT_EQ(o.metadata.at("seed"), "3");
}

TEST(TrajectoryObservation, ErrorsNameTheTrajectoryOrTheVertexList) {
  io::TrajectoryData t = moving_bar();
  io::ObservationRequest request;
  request.vertices = std::vector<int> { 0, 20 };
  request.vertices_source = "ids.txt";
  io::test::expect_input_error([&] { io::observe_trajectory(t, "bar.h5", request); },
      { "ids.txt", "vertex id 20", "bar.h5" });
  request.vertices = std::vector<int> { -1 };
  io::test::expect_input_error(
      [&] { io::observe_trajectory(t, "bar.h5", request); }, { "ids.txt", "vertex id -1" });
  request.vertices = std::nullopt;
  request.visible_fraction = 1.5;
  io::test::expect_input_error([&] { io::observe_trajectory(t, "bar.h5", request); }, { "1.5" });
  request.visible_fraction = 0.5;
  t.time[2] = 0.6;
  io::test::expect_input_error(
      [&] { io::observe_trajectory(t, "bar.h5", request); }, { "bar.h5: /time" });
  t.tets.resize(0, 4);
  io::test::expect_input_error(
      [&] { io::observe_trajectory(t, "bar.h5", request); }, { "bar.h5: /tets", "missing" });
}

} // namespace
