// The learning loop's records: a forward outcome has an error exactly when its simulation
// completed, and the accessors over both kinds of step read the right fields.
#include <elastolearn/learn/iteration_record.hpp>

#include <gtest/gtest.h>

#include <stdexcept>

namespace elastolearn::learn {
namespace {

TEST(IterationRecord, AnErrorExistsOnlyForACompletedSimulation) {
  ErrorSummary e;
  e.rms = 0.5;
  const ForwardOutcome done = ForwardOutcome::completed(e, 2);
  EXPECT_TRUE(done.completed());
  EXPECT_EQ(done.error().rms, 0.5);
  EXPECT_EQ(done.message(), "");
  EXPECT_EQ(done.seconds(), 2);
  for (const ForwardOutcome& failed :
      { ForwardOutcome::diverged("diverged at frame 3", 1), ForwardOutcome::unstable("x", 0) }) {
    EXPECT_FALSE(failed.completed());
    EXPECT_THROW((void)failed.error(), std::logic_error) << to_string(failed.status());
    EXPECT_FALSE(failed.message().empty());
  }
  for (ForwardStatus s :
      { ForwardStatus::completed, ForwardStatus::diverged, ForwardStatus::unstable })
    EXPECT_EQ(forward_status_from_string(to_string(s)), s);
  EXPECT_EQ(forward_status_from_string("finished"), std::nullopt);
}

TEST(IterationRecord, AccessorsReadEitherKindOfStep) {
  SpaceTimeStages t;
  t.seconds_pod = 1;
  t.seconds_constrained = 2;
  t.seconds_space_time = 4;
  t.seconds_reconstruction = 8;
  const IterationRecord loop = LoopRecord { 3, ForwardOutcome::completed({}, 16), t };
  const IterationRecord damped
      = LoopRecord { 4, ForwardOutcome::diverged("frame 2", 32), DampedUpdate {} };
  const IterationRecord step
      = ForwardFitRecord { 5, ForwardOutcome::unstable("unstable", 64), false, 7 };
  EXPECT_EQ(iteration_of(loop), 3);
  EXPECT_EQ(iteration_of(step), 5);
  EXPECT_EQ(seconds_of(loop), 31); // forward + every stage
  EXPECT_EQ(seconds_of(damped), 32); // no stages
  EXPECT_EQ(seconds_of(step), 64);
  EXPECT_NE(stages_of(loop), nullptr);
  EXPECT_EQ(stages_of(damped), nullptr);
  EXPECT_EQ(stages_of(step), nullptr);
  EXPECT_TRUE(std::get<LoopRecord>(damped).damped_update());
  EXPECT_FALSE(std::get<LoopRecord>(loop).damped_update());
  EXPECT_EQ(forward_fit_of(loop), nullptr);
  ASSERT_NE(forward_fit_of(step), nullptr);
  EXPECT_EQ(forward_fit_of(step)->centres, 7);
  EXPECT_EQ(forward_of(step).status(), ForwardStatus::unstable);
}

} // namespace
} // namespace elastolearn::learn
