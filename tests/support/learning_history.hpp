#pragma once
/// \file Comparing the histories of two learning runs step by step (learn::IterationRecord).
#include <elastolearn/learn/iteration_record.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <vector>

namespace elastolearn::test {

/// The forward error RMS of a step (−1 when its simulation did not complete).
inline double forward_rms(const learn::IterationRecord& r) {
  const learn::ForwardOutcome& f = learn::forward_of(r);
  return f.completed() ? f.error().rms : -1.0;
}

/// The control-force RMS of a step (−1 without trajectory stages).
inline double control_rms(const learn::IterationRecord& r) {
  const learn::SpaceTimeStages* t = learn::stages_of(r);
  return t ? t->control_force_rms : -1.0;
}

/// Both runs took the same steps: the same kinds, iterations, forward outcomes, forward errors
/// and control forces, bit for bit (or within `relative_tolerance` of each other, for runs of
/// different builds whose arithmetic rounds differently).
inline void expect_same_steps(const std::vector<learn::IterationRecord>& a,
    const std::vector<learn::IterationRecord>& b, double relative_tolerance = 0) {
  ASSERT_EQ(a.size(), b.size());
  const auto expect_close = [&](double x, double y, size_t i) {
    if (relative_tolerance == 0)
      EXPECT_EQ(x, y) << "step " << i;
    else
      EXPECT_NEAR(x, y, relative_tolerance * std::max(std::abs(x), std::abs(y))) << "step " << i;
  };
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].index(), b[i].index()) << "step " << i;
    EXPECT_EQ(learn::iteration_of(a[i]), learn::iteration_of(b[i])) << "step " << i;
    EXPECT_EQ(learn::forward_of(a[i]).status(), learn::forward_of(b[i]).status()) << "step " << i;
    expect_close(forward_rms(a[i]), forward_rms(b[i]), i);
    expect_close(control_rms(a[i]), control_rms(b[i]), i);
  }
}

} // namespace elastolearn::test
