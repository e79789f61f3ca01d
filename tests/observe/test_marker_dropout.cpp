// Simulated lost markers (issue 20): the lost fraction and the mean burst length are what was
// asked for, lost entries are NaN and marked, and the draw is reproducible from the seed.
#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/marker_dropout.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace elastolearn::observe {
namespace {

Observation constant_observation(int frames, int points) {
  Observation o;
  for (int j = 0; j < points; ++j)
    o.vertex_ids.push_back(j);
  o.dt = 0.01;
  o.positions.assign(static_cast<size_t>(frames), Positions::Constant(points, 3, 0.5));
  return o;
}

/// Lost fraction and mean length of the bursts of loss that start and end inside the motion.
struct BurstStatistics {
  double lost_fraction = 0;
  double mean_burst = 0;
};

BurstStatistics statistics(const Observation& o) {
  BurstStatistics s;
  long lost = 0, bursts = 0, burst_frames = 0;
  for (int j = 0; j < o.num_observed(); ++j) {
    int run = 0;
    bool started_inside = false;
    for (int t = 0; t < o.num_frames(); ++t) {
      if (!o.is_valid(t, j)) {
        ++lost;
        if (run++ == 0)
          started_inside = t > 0;
      } else {
        if (run > 0 && started_inside) {
          ++bursts;
          burst_frames += run;
        }
        run = 0;
      }
    }
  }
  s.lost_fraction = double(lost) / (double(o.num_frames()) * o.num_observed());
  s.mean_burst = bursts > 0 ? double(burst_frames) / double(bursts) : 0;
  return s;
}

TEST(MarkerDropout, LosesTheAskedFractionInBurstsOfTheAskedMeanLength) {
  // 200 points × 1000 frames; bursts of mean L and seen runs of mean L(1 − P)/P make
  // ~200 000 / (L/P) ≈ 8 000 (P = 0.2, L = 5) independent bursts: the lost fraction's relative
  // spread is ~1/√8000 ≈ 1.1 %, the mean burst length's ~(√(L(L−1))/L)/√8000 ≈ 1 %; allow 5 %.
  for (const auto& [fraction, burst] : { std::pair { 0.2, 5.0 }, { 0.5, 3.0 }, { 0.05, 2.0 } }) {
    SCOPED_TRACE(testing::Message() << "P = " << fraction << ", L = " << burst);
    Observation o = constant_observation(1000, 200);
    drop_markers(o, fraction, burst, 11);
    const BurstStatistics s = statistics(o);
    EXPECT_NEAR(s.lost_fraction, fraction, 0.05 * fraction);
    EXPECT_NEAR(s.mean_burst, burst, 0.05 * burst);
    for (int t = 0; t < o.num_frames(); ++t)
      for (int j = 0; j < o.num_observed(); ++j) {
        if (o.is_valid(t, j))
          EXPECT_EQ(o.positions[t](j, 1), 0.5);
        else
          EXPECT_TRUE(std::isnan(o.positions[t](j, 1)));
      }
    EXPECT_NO_THROW(o.validate("dropout"));
  }
  // Above L/(L + 1) the bursts lengthen instead: P = 0.9 with L = 5 gives bursts of mean 9.
  Observation o = constant_observation(1000, 200);
  drop_markers(o, 0.9, 5, 3);
  const BurstStatistics s = statistics(o);
  EXPECT_NEAR(s.lost_fraction, 0.9, 0.05 * 0.9);
  EXPECT_NEAR(s.mean_burst, 9, 0.05 * 9);
}

TEST(MarkerDropout, IsReproducibleFromTheSeedAndKeepsWhatWasLost) {
  Observation a = constant_observation(50, 10), b = a, c = a;
  drop_markers(a, 0.3, 4, 5);
  drop_markers(b, 0.3, 4, 5);
  drop_markers(c, 0.3, 4, 6);
  EXPECT_TRUE((a.valid == b.valid).all());
  EXPECT_FALSE((a.valid == c.valid).all());
  // Dropping again never brings an entry back.
  Observation again = a;
  drop_markers(again, 0.3, 4, 9);
  EXPECT_TRUE((again.valid <= a.valid).all());
  EXPECT_LT(again.num_valid(), a.num_valid());
  // No dropout changes nothing.
  Observation none = constant_observation(50, 10);
  drop_markers(none, 0, 4, 5);
  EXPECT_EQ(none.valid.size(), 0);
  // Everything lost keeps one entry: the observation stays usable.
  Observation tiny = constant_observation(2, 1);
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Observation t = tiny;
    drop_markers(t, 0.99, 50, seed);
    EXPECT_GE(t.num_valid(), 1);
    EXPECT_NO_THROW(t.validate("tiny"));
  }
}

TEST(MarkerDropout, RejectsOutOfRangeArguments) {
  Observation o = constant_observation(10, 2);
  EXPECT_THROW(drop_markers(o, 1.0, 5, 1), InputError);
  EXPECT_THROW(drop_markers(o, -0.1, 5, 1), InputError);
  EXPECT_THROW(drop_markers(o, std::nan(""), 5, 1), InputError);
  EXPECT_THROW(drop_markers(o, 0.2, 0.5, 1), InputError);
  EXPECT_THROW(drop_markers(o, 0.2, INFINITY, 1), InputError);
}

} // namespace
} // namespace elastolearn::observe
