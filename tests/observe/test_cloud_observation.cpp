// Observations from point clouds: a vertex is seen where cloud points lie around it, its position
// is the trajectory estimate's, the result does not depend on the order of the points, and
// mismatched inputs are refused.
#include <elastolearn/capture/surface_samples.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/cloud_observation.hpp>

#include <support/bar_scene.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace elastolearn;

namespace {

/// A 0.4 × 0.1 × 0.1 m bar of 8 × 2 × 2 cells (cell edge 5 cm): its top face (y = 0.1) has a
/// middle row of vertices with neighbours on every side.
struct TopScan {
  sim::Scene scene = test::bar_scene({ .cells = { 8, 2, 2 } });
  std::vector<int> surface = scene.mesh.surface_vertices();
  std::vector<Positions> frames; ///< rest, then moved 1 cm up
  capture::PointCloudSequence clouds;
  static constexpr double sigma = 0.01; ///< reach 3.7 cm: less than a cell edge

  TopScan() {
    const Positions rest = scene.mesh.rest_positions();
    Positions up = rest;
    up.col(1).array() += 0.01;
    frames = { rest, up };
    // The top face's surface samples (a lattice of 1.25 cm) in each frame.
    const auto samples = capture::sample_surface(scene.mesh.surface_faces(), 4);
    std::vector<capture::CloudFrame> cloud_frames;
    for (const Positions& x : frames) {
      const Positions all = samples.positions(x);
      std::vector<Eigen::Index> top;
      for (Eigen::Index i = 0; i < all.rows(); ++i)
        if (all(i, 1) > x.col(1).maxCoeff() - 1e-9)
          top.push_back(i);
      capture::CloudFrame f;
      f.points.resize(static_cast<Eigen::Index>(top.size()), 3);
      for (std::size_t i = 0; i < top.size(); ++i)
        f.points.row(static_cast<Eigen::Index>(i)) = all.row(top[i]);
      cloud_frames.push_back(f);
    }
    clouds = capture::PointCloudSequence::from_frames(cloud_frames, 0.01, 0, "scan");
  }
  observe::CloudObservationOptions options() const {
    observe::CloudObservationOptions o;
    o.sigma = sigma;
    return o;
  }
};

} // namespace

TEST(CloudObservation, SeesTheVerticesTheCloudCoversAtTheEstimatesPositions) {
  const TopScan s;
  const auto observed = observe::observe_clouds(s.surface, s.frames, s.clouds, s.options());
  ASSERT_EQ(observed.num_frames(), 2);
  ASSERT_EQ(observed.vertex_ids, s.surface);
  EXPECT_DOUBLE_EQ(observed.dt, 0.01);
  int seen_middle = 0, seen_below = 0, middle = 0;
  for (int t = 0; t < 2; ++t)
    for (int j = 0; j < observed.num_observed(); ++j) {
      const Eigen::RowVector3d p = s.frames[t].row(s.surface[j]);
      // Every entry is the estimate's position (seen or not).
      EXPECT_EQ(observed.positions[t].row(j), p);
      const double rest_y = s.frames[0](s.surface[j], 1);
      const double rest_z = s.frames[0](s.surface[j], 2);
      const bool top_middle = rest_y > 0.1 - 1e-9 && std::abs(rest_z - 0.05) < 1e-9 && p.x() > 1e-9
          && p.x() < 0.4 - 1e-9;
      middle += top_middle;
      seen_middle += top_middle && observed.is_valid(t, j);
      // Vertices a cell below the top face have no point within the 3.7 cm reach.
      seen_below += rest_y < 0.05 + 1e-9 && observed.is_valid(t, j);
    }
  EXPECT_EQ(middle, 2 * 7);
  EXPECT_EQ(seen_middle, middle) << "a vertex in the middle of the scanned face is seen";
  EXPECT_EQ(seen_below, 0) << "a vertex with no point nearby is not";
}

TEST(CloudObservation, DoesNotDependOnTheOrderOfThePoints) {
  TopScan s;
  const auto observed = observe::observe_clouds(s.surface, s.frames, s.clouds, s.options());
  std::vector<Eigen::Index> order(static_cast<std::size_t>(s.clouds.num_points()));
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = static_cast<Eigen::Index>(i);
  // Shuffle within each frame.
  std::mt19937 rng(5);
  for (int t = 0; t < s.clouds.num_frames(); ++t)
    std::shuffle(order.begin() + s.clouds.offsets[t], order.begin() + s.clouds.offsets[t + 1], rng);
  capture::PointCloudSequence shuffled = s.clouds;
  for (std::size_t i = 0; i < order.size(); ++i)
    shuffled.points.row(static_cast<Eigen::Index>(i)) = s.clouds.points.row(order[i]);
  const auto again = observe::observe_clouds(s.surface, s.frames, shuffled, s.options());
  EXPECT_TRUE((again.valid == observed.valid).all());
}

TEST(CloudObservation, MismatchedInputsAreRefused) {
  const TopScan s;
  const auto refused = [](auto&& call, const std::string& words) {
    try {
      call();
      ADD_FAILURE() << "accepted; expected an error with '" << words << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused([&] { observe::observe_clouds(s.surface, { s.frames[0] }, s.clouds, s.options()); },
      "the trajectory has 1 frames, the clouds 2");
  refused([&] { observe::observe_clouds({ 100000 }, s.frames, s.clouds, s.options()); },
      "vertex id 100000 is outside");
  auto far = s.frames;
  for (auto& x : far)
    x.col(0).array() += 10;
  refused([&] { observe::observe_clouds(s.surface, far, s.clouds, s.options()); },
      "no surface vertex has cloud points within reach");
  auto o = s.options();
  o.sigma = 0;
  refused([&] { observe::observe_clouds(s.surface, s.frames, s.clouds, o); }, "sigma");
}
