#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include "../support/bar_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace elastolearn;

namespace {

/// A stiff bar (E = 1e9 Pa: displacements of ~10⁻⁵ of its size, so the response is linear to
/// ~10⁻⁵) under gravity, a tip load released after 10 steps and a swing.
sim::Scene stiff_bar() {
  sim::Scene s = test::bar_scene({ .young = 1e9, .alpha1 = 1e-4, .dt = 1e-4, .frames = 30 });
  s.loads.push_back({ mesh::vertices_with_max_coordinate(s.mesh, 0, 1e-9), Vec3(0, 0, 50), 1e-3 });
  s.initial.kind = sim::InitialCondition::Kind::Velocity;
  s.initial.angular_velocity = Vec3(0, 0.02, 0);
  return s;
}

/// max over frames and dofs of |(x_b − X) − factor (x_a − X)|, relative to max |x_b − X|.
double linear_scaling_error(
    const sim::ForwardRun& a, const sim::ForwardRun& b, const VecX& rest, double factor) {
  double error = 0, size = 0;
  for (size_t t = 0; t < a.positions.size(); ++t) {
    error = std::max(
        error, ((b.positions[t] - rest) - factor * (a.positions[t] - rest)).cwiseAbs().maxCoeff());
    size = std::max(size, (b.positions[t] - rest).cwiseAbs().maxCoeff());
  }
  return error / size;
}

VecX flat_rest(const sim::Scene& s) {
  const Positions& p = s.mesh.rest_positions();
  return Eigen::Map<const VecX>(p.data(), p.size());
}

} // namespace

TEST(AmplifiedScene, ScalesEveryDriveSoThatASmallMotionScalesLinearly) {
  const sim::Scene scene = stiff_bar();
  const auto once = sim::simulate_positions(scene);
  const auto twice = sim::simulate_positions(sim::amplified_scene(scene, 2));
  ASSERT_TRUE(once.completed && twice.completed);
  EXPECT_LT(linear_scaling_error(once, twice, flat_rest(scene), 2), 1e-4);
  // Without the load, the swing or gravity scaled the ratio would be off by far more.
  sim::Scene partly = sim::amplified_scene(scene, 2);
  partly.loads = scene.loads;
  const auto wrong = sim::simulate_positions(partly);
  ASSERT_TRUE(wrong.completed);
  EXPECT_GT(linear_scaling_error(once, wrong, flat_rest(scene), 2), 1e-2);
}

TEST(AmplifiedScene, ScalesKeyframesAndARecordedInitialState) {
  sim::Scene scene = stiff_bar();
  sim::KeyframeMotion cap;
  cap.vertices = mesh::vertices_with_max_coordinate(scene.mesh, 0, 1e-9);
  cap.amplitude = Vec3(0, 1e-5, 0);
  cap.frequency = 100;
  scene.keyframes.push_back(cap);
  scene.loads.clear();
  // Start from a frame of the swing, recorded.
  const auto swing = sim::simulate_positions(scene);
  ASSERT_TRUE(swing.completed);
  scene.initial.kind = sim::InitialCondition::Kind::Recorded;
  const VecX velocity = (swing.positions[11] - swing.positions[9]) / (2 * scene.dt);
  scene.initial.positions = unflatten(swing.positions[10]);
  scene.initial.velocities = unflatten(velocity);
  scene.initial.time = 10 * scene.dt;
  const auto once = sim::simulate_positions(scene);
  const auto amplified = sim::simulate_positions(sim::amplified_scene(scene, 1.5));
  ASSERT_TRUE(once.completed && amplified.completed);
  EXPECT_LT(linear_scaling_error(once, amplified, flat_rest(scene), 1.5), 1e-4);
}

TEST(AmplifiedScene, RefusesAFactorThatIsNotFinite) {
  EXPECT_THROW(sim::amplified_scene(stiff_bar(), std::nan("")), InputError);
  EXPECT_THROW(
      sim::amplified_scene(stiff_bar(), std::numeric_limits<double>::infinity()), InputError);
}
