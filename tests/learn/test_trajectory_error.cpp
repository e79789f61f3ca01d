// Trajectory errors (paper 000 Table 1's err_L): exact values on hand-made trajectories,
// vertex subsets, observation errors, percentages and input validation.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/trajectory_error.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// T frames of n vertices at (t + v, 0, 0).
std::vector<VecX> ramp(int frames, int n) {
  std::vector<VecX> out(frames, VecX::Zero(3 * n));
  for (int t = 0; t < frames; ++t)
    for (int v = 0; v < n; ++v)
      out[t][3 * v] = t + v;
  return out;
}

} // namespace

TEST(TrajectoryError, IdenticalTrajectoriesHaveZeroError) {
  const auto a = ramp(5, 4);
  const ErrorSummary e = position_error(a, a);
  EXPECT_EQ(e.max, 0.0);
  EXPECT_EQ(e.mean, 0.0);
  EXPECT_EQ(e.rms, 0.0);
  EXPECT_EQ(e.samples, 20);
}

TEST(TrajectoryError, MaxMeanRmsAndWorstLocationAreExact) {
  const auto a = ramp(3, 4);
  auto b = a;
  b[1].segment<3>(3 * 2) += Vec3(3, 4, 0); // error 5 at frame 1, vertex 2
  b[2].segment<3>(3 * 0) += Vec3(0, 0, 1); // error 1 at frame 2, vertex 0
  const ErrorSummary e = position_error(a, b);
  EXPECT_DOUBLE_EQ(e.max, 5.0);
  EXPECT_EQ(e.worst_frame, 1);
  EXPECT_EQ(e.worst_vertex, 2);
  EXPECT_DOUBLE_EQ(e.mean, 6.0 / 12.0);
  EXPECT_DOUBLE_EQ(e.rms, std::sqrt(26.0 / 12.0));
  // A subset that leaves out vertex 2 sees only the error of 1.
  const ErrorSummary s = position_error(a, b, { 0, 3 });
  EXPECT_DOUBLE_EQ(s.max, 1.0);
  EXPECT_EQ(s.worst_vertex, 0);
  EXPECT_EQ(s.samples, 6);
  EXPECT_DOUBLE_EQ(s.mean, 1.0 / 6.0);
}

TEST(TrajectoryError, ComparesTheCommonFramesOnly) {
  const auto a = ramp(5, 2);
  auto b = ramp(3, 2);
  b[2][1] = 2.0;
  const ErrorSummary e = position_error(a, b);
  EXPECT_EQ(e.samples, 6);
  EXPECT_DOUBLE_EQ(e.max, 2.0);
  EXPECT_EQ(e.worst_frame, 2);
}

TEST(TrajectoryError, PercentScalesByTheLength) {
  ErrorSummary e;
  e.max = 0.02;
  e.mean = 0.01;
  e.rms = 0.015;
  e.worst_frame = 4;
  const ErrorSummary p = as_percent_of(e, 0.5);
  EXPECT_DOUBLE_EQ(p.max, 4.0);
  EXPECT_DOUBLE_EQ(p.mean, 2.0);
  EXPECT_DOUBLE_EQ(p.rms, 3.0);
  EXPECT_EQ(p.worst_frame, 4);
  EXPECT_THROW(as_percent_of(e, 0.0), InputError);
  EXPECT_THROW(as_percent_of(e, NAN), InputError);
}

TEST(TrajectoryError, ObservationErrorUsesTheObservedVerticesInTheirOrder) {
  const auto frames = ramp(4, 5);
  observe::Observation obs;
  obs.dt = 0.01;
  obs.vertex_ids = { 4, 1 };
  for (int t = 0; t < 3; ++t) {
    Positions p(2, 3);
    p.row(0) = frames[t].segment<3>(12).transpose();
    p.row(1) = frames[t].segment<3>(3).transpose();
    obs.positions.push_back(p);
  }
  EXPECT_EQ(observation_error(frames, obs).max, 0.0);
  obs.positions[2](1, 1) += 0.25; // vertex 1 at frame 2
  const ErrorSummary e = observation_error(frames, obs);
  EXPECT_DOUBLE_EQ(e.max, 0.25);
  EXPECT_EQ(e.worst_vertex, 1);
  EXPECT_EQ(e.worst_frame, 2);
  EXPECT_EQ(e.samples, 6);
  obs.vertex_ids[0] = 5;
  EXPECT_THROW(observation_error(frames, obs), InputError);
}

TEST(TrajectoryError, RejectsEmptyAndMismatchedInput) {
  const auto a = ramp(3, 4);
  EXPECT_THROW(position_error(a, {}), InputError);
  EXPECT_THROW(position_error({}, a), InputError);
  EXPECT_THROW(position_error(a, ramp(3, 5)), InputError);
  EXPECT_THROW(position_error(a, a, { 4 }), InputError);
  EXPECT_THROW(position_error(a, a, { -1 }), InputError);
}

TEST(TrajectoryError, CombinedErrorIsTheErrorOverTheUnionOfThePairs) {
  // Two motions of different sizes: the combined summary is the one of all their pairs at once
  // (the second motion's error 5 is the max, at its own frame and vertex); one part is returned
  // as it is, and no part is the empty summary.
  const auto a = ramp(3, 4), c = ramp(2, 3);
  auto b = a, d = c;
  b[2].segment<3>(3 * 0) += Vec3(0, 0, 1); // error 1 in the first motion
  d[1].segment<3>(3 * 2) += Vec3(3, 4, 0); // error 5 at frame 1, vertex 2 of the second
  const ErrorSummary first = position_error(a, b), second = position_error(c, d);
  const std::vector<ErrorSummary> parts { first, second };
  const ErrorSummary both = combined_error(parts);
  EXPECT_EQ(both.samples, 12 + 6);
  EXPECT_DOUBLE_EQ(both.max, 5.0);
  EXPECT_EQ(both.worst_frame, 1);
  EXPECT_EQ(both.worst_vertex, 2);
  EXPECT_DOUBLE_EQ(both.mean, 6.0 / 18.0);
  EXPECT_DOUBLE_EQ(both.rms, std::sqrt(26.0 / 18.0));
  const ErrorSummary one = combined_error(std::span(parts).first(1));
  EXPECT_EQ(one.rms, first.rms);
  EXPECT_EQ(one.mean, first.mean);
  EXPECT_EQ(one.samples, first.samples);
  EXPECT_EQ(combined_error({}).samples, 0);
  EXPECT_EQ(combined_error({}).worst_frame, -1);
}
