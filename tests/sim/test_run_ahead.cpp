// sim::RunAhead: a simulation stepping on its own thread publishes the same frames as stepping
// in the caller's thread, reports a divergence at its frame, and stops when dropped early.
#include <elastolearn/sim/forward_run.hpp>
#include <elastolearn/sim/run_ahead.hpp>

#include <support/bar_scene.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;

TEST(RunAhead, PublishesTheFramesOfTheSameSimulationSteppedInPlace) {
  const sim::Scene scene = test::swinging_bar(30);
  const sim::ForwardRun in_place = sim::simulate_positions(scene);
  ASSERT_TRUE(in_place.completed) << in_place.message;
  sim::Simulator simulator(scene);
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  sim::RunAhead ahead(simulator, scene.frames);
  EXPECT_EQ(ahead.positions(0), in_place.positions[0]);
  for (int t = 1; t <= scene.frames; ++t) {
    ASSERT_TRUE(ahead.wait_for(t)) << ahead.message();
    // Deterministic: the same states to the last bit, whichever thread stepped.
    EXPECT_EQ(ahead.positions(t), in_place.positions[static_cast<size_t>(t)]) << "frame " << t;
    EXPECT_DOUBLE_EQ(ahead.time(t), t * scene.dt);
  }
  EXPECT_TRUE(ahead.message().empty());
}

TEST(RunAhead, ReportsADivergenceAtItsFrame) {
  // Newton cannot solve the first step: frame 1 fails.
  const sim::Scene scene = test::failing_first_step(test::swinging_bar(30));
  sim::Simulator simulator(scene);
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  sim::RunAhead ahead(simulator, scene.frames);
  EXPECT_FALSE(ahead.wait_for(1));
  EXPECT_FALSE(ahead.wait_for(scene.frames));
  EXPECT_EQ(ahead.message().rfind("frame 1: ", 0), 0u) << ahead.message();
}

TEST(RunAhead, StopsWhenDroppedBeforeItsEnd) {
  // Dropped after its first frame: the destructor stops the stepping and joins (a hang here is
  // the failure), and the simulator has taken at most the frames it was asked for.
  sim::Scene scene = test::swinging_bar(30);
  scene.frames = 100000;
  sim::Simulator simulator(scene);
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  {
    sim::RunAhead ahead(simulator, scene.frames);
    ASSERT_TRUE(ahead.wait_for(1));
  }
  EXPECT_GE(simulator.step_index(), 1);
  EXPECT_LT(simulator.step_index(), scene.frames);
}
