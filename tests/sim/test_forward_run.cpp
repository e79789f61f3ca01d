// A forward run kept whole (sim/forward_run.hpp): every state of run_simulation, a divergence as
// a result, and the scene with a correction attached.
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/sim/forward_run.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <support/bar_scene.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;

TEST(ForwardRun, KeepsEveryStateOfTheSimulationAndTheInitialVelocity) {
  const sim::Scene scene = test::swinging_bar(20);
  std::vector<VecX> streamed;
  VecX v0;
  const auto report
      = sim::run_simulation(scene, [&](int frame, double, const VecX& x, const VecX& v) {
          if (frame == 0)
            v0 = v;
          streamed.push_back(x);
        });
  ASSERT_TRUE(report.completed) << report.message;

  const sim::ForwardRun run = sim::simulate_positions(scene);
  EXPECT_TRUE(run.completed);
  EXPECT_TRUE(run.message.empty()) << run.message;
  ASSERT_EQ(run.positions.size(), static_cast<size_t>(scene.frames) + 1);
  // The same deterministic simulation: the same states to the last bit.
  for (size_t i = 0; i < run.positions.size(); ++i)
    EXPECT_EQ(run.positions[i], streamed[i]) << "frame " << i;
  EXPECT_EQ(run.initial_velocity, v0);
  EXPECT_GT(run.initial_velocity.norm(), 0);
}

TEST(ForwardRun, ADivergenceIsAResultWithoutPositions) {
  // Newton cannot solve the first step: the run stops at frame 1.
  const sim::Scene scene = test::failing_first_step(test::swinging_bar(20));
  const sim::ForwardRun run = sim::simulate_positions(scene);
  EXPECT_FALSE(run.completed);
  EXPECT_TRUE(run.positions.empty());
  EXPECT_NE(run.message.find("frame 1"), std::string::npos) << run.message;
}

TEST(ForwardRun, WithCorrectionAttachesOnlyTheCorrection) {
  const sim::Scene scene = test::swinging_bar(20);
  material::AnalyticCorrection::Parameters p;
  p.a = 1e8; // (σ − 1)³ stiffening, enough to change the swing
  const auto correction = std::make_shared<material::AnalyticCorrection>(p);
  const sim::Scene corrected = sim::with_correction(scene, correction);
  EXPECT_EQ(corrected.material.correction, correction);
  EXPECT_EQ(scene.material.correction, nullptr); // the original is untouched
  EXPECT_EQ(corrected.material.elastic, scene.material.elastic);
  EXPECT_EQ(corrected.material.damping, scene.material.damping);
  EXPECT_EQ(corrected.frames, scene.frames);
  EXPECT_EQ(corrected.fixed_vertices, scene.fixed_vertices);

  const sim::ForwardRun plain = sim::simulate_positions(scene);
  const sim::ForwardRun stiffened = sim::simulate_positions(corrected);
  ASSERT_TRUE(plain.completed && stiffened.completed) << stiffened.message;
  EXPECT_GT((plain.positions.back() - stiffened.positions.back()).norm(), 1e-9);
  // Null removes a correction again.
  EXPECT_EQ(sim::with_correction(corrected, nullptr).material.correction, nullptr);
}
