// check_larger_motion (the validation choice's larger motion): substeps are the solver's
// business; a material that follows the recorded motion but diverges in the larger one fails.
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/larger_motion_check.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/forward_run.hpp>

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

/// Largest |σ − 1| of the scene's larger motion.
double larger_motion_strain(const sim::Scene& scene) {
  const sim::ForwardRun run = sim::simulate_positions(sim::amplified_scene(scene, kLargerMotion));
  EXPECT_TRUE(run.completed);
  const MatX s = collect_stretches(ReconstructionMesh(scene.mesh, scene.material), run.positions);
  return std::max(s.maxCoeff() - 1, 1 - s.minCoeff());
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
  EXPECT_EQ(check.message.rfind("droop: diverged at frame ", 0), 0u) << check.message;
  // The nominal alone follows the larger motion.
  EXPECT_TRUE(check_larger_motion(scene, "droop").completed);
}
