// Observation::validate: each kind of bad observation gives an InputError that names the source,
// the field and the offending value; a consistent observation passes.
#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/observation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace elastolearn;
using namespace elastolearn::observe;

namespace {

Observation valid_observation() {
  Observation obs;
  obs.vertex_ids = { 4, 0, 9 };
  obs.dt = 0.01;
  for (int t = 0; t < 5; ++t)
    obs.positions.push_back(Positions::Constant(3, 3, 0.1 * t));
  return obs;
}

/// Expect validate(10 vertices, 5 frames, dt 0.01) to throw an InputError containing every part.
void expect_rejected(const std::function<void(Observation&)>& breaker,
    const std::vector<std::string>& parts, int frames = 5, double dt = 0.01) {
  Observation obs = valid_observation();
  breaker(obs);
  try {
    obs.validate(10, frames, dt, "capture.h5");
    ADD_FAILURE() << "no error for " << parts.back();
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("capture.h5"), std::string::npos) << message;
    for (const auto& part : parts)
      EXPECT_NE(message.find(part), std::string::npos) << message << " lacks " << part;
  }
}

} // namespace

TEST(Observation, ValidPasses) {
  const Observation obs = valid_observation();
  EXPECT_NO_THROW(obs.validate(10, 5, 0.01, "capture.h5"));
  EXPECT_NO_THROW(obs.validate(10, -1, 0.0, "capture.h5")); // frames and dt unchecked
  EXPECT_EQ(obs.num_observed(), 3);
  EXPECT_EQ(obs.num_frames(), 5);
}

TEST(Observation, RejectsEachProblemWithAClearMessage) {
  expect_rejected([](Observation& o) { o.vertex_ids[1] = 10; },
      { "/observed/vertex_ids", "10", "out of range [0, 10)" });
  expect_rejected([](Observation& o) { o.vertex_ids[2] = -3; }, { "vertex_ids", "-3", "negative" });
  expect_rejected([](Observation& o) { o.vertex_ids[2] = 4; }, { "vertex_ids", "4", "twice" });
  expect_rejected([](Observation& o) { o.vertex_ids.clear(); }, { "no observed vertices" });
  expect_rejected([](Observation& o) { o.positions[3](1, 2) = std::nan(""); },
      { "/observed/positions", "frame 3", "non-finite", "vertex 0" });
  expect_rejected([](Observation& o) { o.positions[2] = Positions::Zero(2, 3); },
      { "/observed/positions", "frame 2", "2 rows" });
  expect_rejected([](Observation& o) { o.positions.clear(); }, { "no frames" });
  expect_rejected([](Observation&) {}, { "/observed/positions", "5 frames", "expects 6" }, 6);
  expect_rejected([](Observation&) {}, { "dt", "0.01", "0.02" }, 5, 0.02);
  expect_rejected([](Observation& o) { o.dt = -1; }, { "dt", "positive" });
  expect_rejected([](Observation& o) { o.start_time = INFINITY; }, { "/time", "start time" });
}

TEST(Observation, LostEntriesMayHoldAnythingAndTheMaskIsChecked) {
  Observation obs = valid_observation();
  obs.valid = ValidityMask::Ones(5, 3);
  obs.valid(2, 1) = 0;
  obs.valid(3, 2) = 0;
  obs.positions[2].row(1).setConstant(std::nan(""));
  obs.positions[3].row(2) << INFINITY, -1e308, 0;
  EXPECT_NO_THROW(obs.validate(10, 5, 0.01, "capture.h5"));
  EXPECT_EQ(obs.num_valid(), 13);
  EXPECT_TRUE(obs.has_lost_entries());
  EXPECT_FALSE(obs.is_valid(2, 1));
  EXPECT_TRUE(obs.is_valid(2, 0));
  // A vertex never seen is allowed (ignored).
  obs.valid.col(0).setZero();
  EXPECT_NO_THROW(obs.validate(10, 5, 0.01, "capture.h5"));

  expect_rejected(
      [](Observation& o) {
        o.valid = ValidityMask::Ones(5, 3);
        o.valid(1, 2) = 0;
        o.positions[1](1, 0) = std::nan(""); // vertex 0 is seen in frame 1
      },
      { "/observed/positions", "frame 1", "nan", "vertex 0", "marks as seen" });
  expect_rejected([](Observation& o) { o.valid = ValidityMask::Ones(4, 3); },
      { "/observed/valid", "(4, 3)", "expected (5, 3)" });
  expect_rejected(
      [](Observation& o) {
        o.valid = ValidityMask::Ones(5, 3);
        o.valid(4, 1) = 7;
      },
      { "/observed/valid", "frame 4", "value 7", "vertex 0" });
  expect_rejected([](Observation& o) { o.valid = ValidityMask::Zero(5, 3); },
      { "/observed/valid", "every entry is 0" });
}

TEST(Observation, FrameRangeKeepsTheMaskOfItsFrames) {
  Observation obs = valid_observation();
  obs.start_time = 1;
  obs.valid = ValidityMask::Ones(5, 3);
  obs.valid(3, 2) = 0;
  const Observation part = obs.frame_range(2, 4);
  EXPECT_EQ(part.num_frames(), 3);
  EXPECT_DOUBLE_EQ(part.start_time, 1.02);
  EXPECT_EQ(part.positions[0], obs.positions[2]);
  ASSERT_EQ(part.valid.rows(), 3);
  EXPECT_FALSE(part.is_valid(1, 2));
  EXPECT_EQ(part.num_valid(), 8);
  EXPECT_EQ(valid_observation().frame_range(1, 1).valid.size(), 0);
  EXPECT_THROW(obs.frame_range(3, 5), InputError);
  EXPECT_THROW(obs.frame_range(2, 1), InputError);
}

TEST(UniformTimeStep, AcceptsRoundingAndRejectsGaps) {
  std::vector<double> time;
  double t = 0;
  for (int i = 0; i < 100; ++i, t += 0.1)
    time.push_back(t); // accumulated rounding, as a simulator records it
  EXPECT_NEAR(uniform_time_step(time, "traj.h5"), 0.1, 1e-15);
  time[50] += 0.05;
  EXPECT_THROW(uniform_time_step(time, "traj.h5"), InputError);
  EXPECT_THROW(uniform_time_step({ 0.0 }, "traj.h5"), InputError);
  EXPECT_THROW(uniform_time_step({ 1.0, 0.5 }, "traj.h5"), InputError);
}
