// check_larger_motion (the validation choice's larger motion and droop): substeps are the
// solver's business; a material that follows the recorded motion but diverges in the larger one,
// or cannot hold the droop, fails; the droop's load makes the reference droop as far as asked.
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/larger_motion_check.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/forward_run.hpp>
#include <elastolearn/sim/simulator.hpp>

#include "../support/bar_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// A bar (E = 1 MPa, ν = 0.4) drooping from rest under gravity for 0.24 s: strains of a few
/// percent, 6 % in the larger motion.
sim::Scene droop(double dt) {
  return test::bar_scene({ .young = 1e6, .dt = dt, .frames = static_cast<int>(0.24 / dt) });
}

/// The scene with the correction Nᵢ = a (σᵢ − 1)³ (a < 0 softens).
sim::Scene with_cubic(sim::Scene scene, double a) {
  scene.material.correction = std::make_shared<material::AnalyticCorrection>(
      material::AnalyticCorrection::Parameters { .a = a });
  return scene;
}

/// The scene held statically under the body acceleration `a` alone, from rest.
sim::Scene held_under(sim::Scene scene, const Vec3& a) {
  scene.initial = {};
  scene.initial.kind = sim::InitialCondition::Kind::StaticLoad;
  scene.gravity = a;
  return scene;
}

/// Largest |σ − 1| of the scene's larger motion.
double larger_motion_strain(const sim::Scene& scene) {
  const sim::ForwardRun run = sim::simulate_positions(sim::amplified_scene(scene, kLargerMotion));
  EXPECT_TRUE(run.completed);
  const MatX s = collect_stretches(ReconstructionMesh(scene.mesh, scene.material), run.positions);
  return std::max(s.maxCoeff() - 1, 1 - s.minCoeff());
}

/// The largest vertex displacement of `x` from `rest` [m].
double largest_displacement(const VecX& x, const VecX& rest) {
  double largest = 0;
  for (Eigen::Index v = 0; v < x.size() / 3; ++v)
    largest = std::max(largest, (x.segment<3>(3 * v) - rest.segment<3>(3 * v)).norm());
  return largest;
}

} // namespace

TEST(LargerMotionCheck, PassesAStableCorrectionWhoseRunNeedsSubsteps) {
  // A stiffening cubic is stable everywhere. With at most 3 Newton iterations per solve some
  // steps converge only in substeps: the solver's business, not the material's.
  sim::Scene scene = with_cubic(droop(4e-3), 1e8);
  scene.newton.max_iterations = 3;
  scene.newton.retry_exact_tangent = false;
  const LargerMotionCheck check = check_larger_motion(scene, "droop");
  EXPECT_TRUE(check.checked);
  EXPECT_TRUE(check.completed) << check.message;
  EXPECT_GT(check.first_substepped_frame, 0) << "the test needs a run that substeps";
  EXPECT_TRUE(check.message.empty());
}

TEST(LargerMotionCheck, FailsAMaterialThatFollowsTheRecordedMotionButNotALargerOne) {
  // The softening 3|a|(σ − 1)² equals the nominal's stretch stiffness λ + 2μ ≈ 2.14 MPa at the
  // nominal's larger-motion strain: the recorded motion (2/3 of that strain) stays short of it,
  // the larger one runs into it and diverges.
  const sim::Scene scene = droop(1e-3);
  const double strain = larger_motion_strain(scene);
  ASSERT_GT(strain, 0.03);
  const sim::Scene softened = with_cubic(scene, -2.14e6 / (3 * strain * strain));
  ASSERT_TRUE(sim::simulate_positions(softened).completed);
  const LargerMotionCheck check = check_larger_motion(softened, "droop");
  EXPECT_TRUE(check.checked);
  EXPECT_FALSE(check.completed);
  EXPECT_EQ(check.message.rfind("droop driven 1.5× as hard (diverged at frame ", 0), 0u)
      << check.message;
  // The nominal alone follows the larger motion.
  EXPECT_TRUE(check_larger_motion(scene, "droop").completed);
}

TEST(LargerMotionCheck, FailsAMaterialThatCannotHoldTheDroop) {
  // The bar at rest without gravity: its recorded motion, and the one driven harder, stay at
  // rest. Under a body load of 3 g the nominal droops statically to strains of ~6 %; the
  // softening cubic cancels the nominal's stretch stiffness at 3 %, so that droop has no
  // equilibrium, and the check fails in it, naming the droop.
  sim::Scene scene = droop(4e-3);
  scene.gravity.setZero();
  scene.frames = 5;
  const Vec3 load(0, -3 * 9.81, 0);
  EXPECT_TRUE(check_larger_motion(scene, "rest", load).completed);
  const sim::Scene softened = with_cubic(scene, -2.14e6 / (3 * 0.03 * 0.03));
  const LargerMotionCheck check = check_larger_motion(softened, "rest", load);
  EXPECT_FALSE(check.completed);
  EXPECT_EQ(check.message.rfind("the droop of rest under a body load of 29.43 m/s", 0), 0u)
      << check.message;
  // Without a droop (zero load) only the motion is checked, and it passes.
  EXPECT_TRUE(check_larger_motion(softened, "rest").completed);
}

TEST(LargerMotionCheck, TheDroopStartsFromTheReferencesEquilibrium) {
  // The bar at rest without gravity under a body load of 3 g (strains of ~6 %), Newton capped at
  // 2 iterations per solve without retries: from rest its load steps cannot converge, and the
  // check fails. Given the reference's equilibrium under the same load (here the material's
  // own), the check starts there and holds the droop.
  sim::Scene scene = droop(4e-3);
  scene.gravity.setZero();
  scene.frames = 5;
  const Vec3 load(0, -3 * 9.81, 0);
  sim::Simulator simulator(held_under(scene, load));
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  const VecX start = simulator.positions();

  sim::Scene strict = scene;
  strict.newton.max_iterations = 2;
  strict.newton.retry_exact_tangent = false;
  strict.newton.max_step_halvings = 0;
  const LargerMotionCheck from_rest = check_larger_motion(strict, "rest", load);
  EXPECT_FALSE(from_rest.completed);
  EXPECT_EQ(from_rest.message.rfind("the droop of rest", 0), 0u) << from_rest.message;
  const LargerMotionCheck from_reference = check_larger_motion(strict, "rest", load, start);
  EXPECT_TRUE(from_reference.completed) << from_reference.message;
}

TEST(LargerMotionCheck, TheDroopLoadMakesTheReferenceDroopAsFarAsTheLargerMotion) {
  // A swing without gravity (ω about z): the body load points along the largest displacement
  // (a tip vertex's, mostly along y), and the reference's static droop under it is kLargerMotion
  // times that displacement. The load is scaled from the linear response to a small trial
  // load, and the swing strains the bar by a few percent: within 10 %.
  sim::Scene scene = droop(4e-3);
  scene.gravity.setZero();
  scene.initial.kind = sim::InitialCondition::Kind::Velocity;
  scene.initial.angular_velocity = Vec3(0, 0, 2.0);
  const sim::ForwardRun run = sim::simulate_positions(scene);
  ASSERT_TRUE(run.completed);
  const VecX rest = flatten(scene.mesh.rest_positions());
  double moved = 0;
  for (const VecX& x : run.positions)
    moved = std::max(moved, largest_displacement(x, rest));
  ASSERT_GT(moved, 0.005);
  const Vec3 a = reference_droop(scene, run.positions).acceleration;
  ASSERT_GT(a.norm(), 0);
  EXPECT_GT(std::abs(a.y()), 0.8 * a.norm()); // mostly across the bar, as the swing moves it
  sim::Simulator simulator(held_under(scene, a));
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  const double drooped = largest_displacement(simulator.positions(), rest);
  EXPECT_NEAR(drooped, kLargerMotion * moved, 0.1 * kLargerMotion * moved);
  // No motion, no droop.
  EXPECT_EQ(reference_droop(scene, { rest, rest }).acceleration, Vec3::Zero());
}
