// The noise of observations (issue 19, "noisy captures"): the estimate recovers a known σ from a
// simulated motion and is ~0 without noise; smoothing to σ changes the data by σ RMS, brings it
// closer to the truth, and leaves a constant-acceleration motion unchanged.
#include <elastolearn/core/error.hpp>
#include <elastolearn/observe/marker_dropout.hpp>
#include <elastolearn/observe/observation_noise.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <support/bar_scene.hpp>

#include <gtest/gtest.h>

namespace elastolearn::observe {
namespace {

std::vector<Positions> droop_frames() {
  const auto run = sim::simulate_positions(test::bar_scene(
      { .cells = { 8, 2, 2 }, .young = 1e6, .alpha1 = 0.01, .dt = 4e-3, .frames = 120 }));
  EXPECT_TRUE(run.completed);
  std::vector<Positions> frames;
  for (const auto& x : run.positions)
    frames.emplace_back(unflatten(x));
  return frames;
}

double rms_distance(const Observation& a, const Observation& b) {
  double sum = 0;
  long n = 0;
  for (size_t t = 0; t < a.positions.size(); ++t) {
    sum += (a.positions[t] - b.positions[t]).squaredNorm();
    n += a.positions[t].size();
  }
  return std::sqrt(sum / static_cast<double>(n));
}

TEST(ObservationNoise, EstimateRecoversTheNoiseLevelAndSmoothingRemovesMostOfIt) {
  const auto frames = droop_frames();
  const auto ids = select_visible_vertices(test::bar_scene({ .cells = { 8, 2, 2 } }).mesh, 0.5, 1);
  const Observation exact = observe_vertices(frames, 4e-3, ids, 0, 1);
  // Noise-free: the droop's own differences (jerk × dt³) are microns at most.
  EXPECT_LT(estimate_noise(exact), 1e-6);
  for (const double sigma : { 1e-4, 1e-3 }) {
    SCOPED_TRACE(testing::Message() << "σ = " << sigma);
    const Observation noisy = observe_vertices(frames, 4e-3, ids, sigma, 3);
    // ~1900 samples per difference order: the median's relative spread is ~3 %; allow 10 %.
    EXPECT_NEAR(estimate_noise(noisy), sigma, 0.1 * sigma);
    const SmoothingResult s = smooth_to_noise(noisy, sigma);
    EXPECT_NEAR(s.rms_change, sigma, 1e-3 * sigma) << "the discrepancy principle";
    EXPECT_GT(s.kappa, 0);
    // The smoothed data is much closer to the truth than the raw data (rms σ).
    EXPECT_LT(rms_distance(s.smoothed, exact), 0.5 * rms_distance(noisy, exact));
  }
}

TEST(ObservationNoise, ConstantAccelerationPassesTheSmootherUnchanged) {
  // Free fall x(t) = x₀ + v t − ½ g t²: its third differences vanish, so any κ keeps it.
  Observation o;
  o.vertex_ids = { 0, 5 };
  o.dt = 0.01;
  for (int t = 0; t < 50; ++t) {
    const double time = t * o.dt;
    Positions p(2, 3);
    p << 0.1 * time, 1 - 4.905 * time * time, 0, 0.2, 0.5 + 0.3 * time - 4.905 * time * time, 0.1;
    o.positions.push_back(p);
  }
  // Round-off: third differences of ~1 m positions (1e-15 m) amplified by at most
  // 1/λ_min(DᵀD) ≈ (50/π)⁶ ≈ 2e7: 2e-8 m; a smoother that does not keep quadratics moves them
  // by ~σ = 1e-3 m.
  const SmoothingResult s = smooth_to_noise(o, 1e-3);
  EXPECT_LT(rms_distance(s.smoothed, o), 1e-7);
  EXPECT_EQ(smooth_to_noise(o, 0).kappa, 0);
  EXPECT_THROW(smooth_to_noise(o, -1), InputError);
}

/// `o` with every lost entry's position replaced by `value`.
Observation with_garbage(Observation o, double value) {
  for (int t = 0; t < o.num_frames(); ++t)
    for (int j = 0; j < o.num_observed(); ++j)
      if (!o.is_valid(t, j))
        o.positions[static_cast<size_t>(t)].row(j).setConstant(value);
  return o;
}

/// RMS distance over the entries seen in `mask`.
double rms_seen_distance(const Observation& a, const Observation& b, const Observation& mask) {
  double sum = 0;
  long n = 0;
  for (int t = 0; t < a.num_frames(); ++t)
    for (int j = 0; j < a.num_observed(); ++j)
      if (mask.is_valid(t, j)) {
        sum += (a.positions[t].row(j) - b.positions[t].row(j)).squaredNorm();
        n += 3;
      }
  return std::sqrt(sum / static_cast<double>(n));
}

TEST(ObservationNoise, LostEntriesChangeNothingWhateverTheirPositions) {
  const auto frames = droop_frames();
  const auto ids = select_visible_vertices(test::bar_scene({ .cells = { 8, 2, 2 } }).mesh, 0.5, 1);
  Observation noisy = observe_vertices(frames, 4e-3, ids, 1e-4, 3);
  drop_markers(noisy, 0.2, 5, 4); // NaN where lost
  ASSERT_TRUE(noisy.has_lost_entries());
  const Observation huge = with_garbage(noisy, 1e300), other = with_garbage(noisy, -3.7);
  const double sigma = estimate_noise(noisy);
  EXPECT_EQ(estimate_noise(huge), sigma);
  EXPECT_EQ(estimate_noise(other), sigma);
  // Only differences over seen frames: σ is still recovered (~1000 samples per order: 10 %).
  EXPECT_NEAR(sigma, 1e-4, 1e-5);
  const SmoothingResult a = smooth_to_noise(noisy, sigma), b = smooth_to_noise(huge, sigma),
                        c = smooth_to_noise(other, sigma);
  EXPECT_EQ(a.kappa, b.kappa);
  EXPECT_EQ(a.rms_change, c.rms_change);
  EXPECT_NEAR(a.rms_change, sigma, 1e-3 * sigma) << "the discrepancy over seen entries";
  for (int t = 0; t < noisy.num_frames(); ++t) {
    // Every entry, lost ones included, is the same finite smoothed value.
    EXPECT_EQ(a.smoothed.positions[t], b.smoothed.positions[t]) << "frame " << t;
    EXPECT_EQ(a.smoothed.positions[t], c.smoothed.positions[t]) << "frame " << t;
    EXPECT_TRUE(a.smoothed.positions[t].allFinite()) << "frame " << t;
  }
  EXPECT_TRUE((a.smoothed.valid == noisy.valid).all()) << "the mask is kept";
  // The smoothed data is closer to the truth than the raw data where seen (as without lost
  // entries), and within a few σ in the gaps (bursts of mean 5 frames, some at the ends of the
  // motion, where the fill extrapolates; measured 2.5σ RMS).
  const Observation exact = observe_vertices(frames, 4e-3, ids, 0, 3);
  EXPECT_LT(rms_seen_distance(a.smoothed, exact, noisy), 0.5 * 1e-4);
  Observation lost_only = noisy;
  lost_only.valid = 1 - noisy.valid;
  EXPECT_LT(rms_seen_distance(a.smoothed, exact, lost_only), 4e-4);
  // σ = 0 only fills, from the seen entries.
  const SmoothingResult filled = smooth_to_noise(huge, 0);
  EXPECT_EQ(filled.kappa, 0);
  for (int t = 0; t < noisy.num_frames(); ++t)
    EXPECT_EQ(filled.smoothed.positions[t], fill_lost_entries(other).positions[t]);
}

TEST(ObservationNoise, GapsOfAConstantAccelerationAreFilledExactly) {
  // Free fall with lost entries inside and at both ends, one point seen only twice (filled
  // linearly, exact for its linear motion) and one never seen (left as it is).
  Observation o;
  o.vertex_ids = { 0, 5, 7, 9 };
  o.dt = 0.01;
  const auto truth = [&](int t, int j) {
    const double time = t * o.dt;
    return Vec3(0.1 * time + j, 1 - 4.905 * time * time, 0.2 * j);
  };
  const auto linear = [&](int t) { return Vec3(0.3 * t * o.dt, 2, 1); };
  o.valid = ValidityMask::Ones(40, 4);
  for (int t = 0; t < 40; ++t) {
    Positions p(4, 3);
    for (int j = 0; j < 2; ++j)
      p.row(j) = truth(t, j).transpose();
    p.row(2) = linear(t).transpose();
    p.row(3).setConstant(std::nan(""));
    o.positions.push_back(p);
    if ((t >= 10 && t < 17) || t < 3 || t >= 36)
      o.valid(t, 0) = 0;
    if (t % 5 == 2)
      o.valid(t, 1) = 0;
    if (t != 11 && t != 20)
      o.valid(t, 2) = 0;
    o.valid(t, 3) = 0;
  }
  const Observation g = with_garbage(o, 1e200);
  const Observation filled = fill_lost_entries(g);
  // Round-off: the fill solves with DᵀD restricted to the gaps, of condition ~(gap length)⁶
  // (the quadratic's); the linear fill's is smaller, 1e-11 on values ~2 m.
  for (int t = 0; t < 40; ++t) {
    for (int j = 0; j < 2; ++j)
      EXPECT_LT((filled.positions[t].row(j).transpose() - truth(t, j)).norm(), 1e-9)
          << "frame " << t << ", point " << j;
    EXPECT_LT((filled.positions[t].row(2).transpose() - linear(t)).norm(), 1e-11) << t;
    EXPECT_EQ(filled.positions[t](3, 0), 1e200) << "never seen: left as it is";
  }
  // The smoother keeps them too (a quadratic has no jerk); round-off grows with W + κDᵀD's
  // condition, which lost rows raise: 2e-7 m measured at κ = 10⁸, where a smoother that does
  // not keep quadratics would move them by ~σ = 1e-3 m.
  const SmoothingResult s = smooth_to_noise(g, 1e-3);
  for (int t = 0; t < 40; ++t)
    for (int j = 0; j < 2; ++j)
      EXPECT_LT((s.smoothed.positions[t].row(j).transpose() - truth(t, j)).norm(), 1e-6);
}

} // namespace
} // namespace elastolearn::observe
