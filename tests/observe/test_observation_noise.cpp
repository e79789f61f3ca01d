// The noise of observations (issue 19, "noisy captures"): the estimate recovers a known σ from a
// simulated motion and is ~0 without noise; smoothing to σ changes the data by σ RMS, brings it
// closer to the truth, and leaves a constant-acceleration motion unchanged.
#include <elastolearn/core/error.hpp>
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

} // namespace
} // namespace elastolearn::observe
