// Errors per frame and their histograms: hand-computed values on two-vertex trajectories, and
// histograms that count every value exactly once (clamped into the end bins).
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/error_distribution.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

namespace elastolearn::learn {
namespace {

VecX frame(std::initializer_list<double> values) {
  VecX x(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double v : values)
    x[i++] = v;
  return x;
}

TEST(ErrorDistribution, VertexErrorsAreDistancesPerFrameAndVertex) {
  // Two vertices, two frames: the second trajectory is offset by (3, 4, 0) at vertex 1 in frame 1.
  const std::vector<VecX> a = { frame({ 0, 0, 0, 1, 0, 0 }), frame({ 0, 0, 0, 1, 0, 0 }) };
  const std::vector<VecX> b = { frame({ 0, 0, 0, 1, 0, 0 }), frame({ 0, 0, 1, 4, 4, 0 }) };
  const Eigen::MatrixXd e = vertex_errors(a, b);
  ASSERT_EQ(e.rows(), 2);
  ASSERT_EQ(e.cols(), 2);
  EXPECT_DOUBLE_EQ(e(0, 0), 0);
  EXPECT_DOUBLE_EQ(e(1, 0), 1);
  EXPECT_DOUBLE_EQ(e(1, 1), 5);
  const Eigen::MatrixXd only_1 = vertex_errors(a, b, { 1 });
  ASSERT_EQ(only_1.cols(), 1);
  EXPECT_DOUBLE_EQ(only_1(1, 0), 5);

  const FrameErrors f = frame_errors(e);
  ASSERT_EQ(f.max.size(), 2u);
  EXPECT_DOUBLE_EQ(f.max[0], 0);
  EXPECT_DOUBLE_EQ(f.max[1], 5);
  EXPECT_DOUBLE_EQ(f.rms[1], std::sqrt((1.0 + 25.0) / 2));
}

TEST(ErrorDistribution, ObservationErrorsUseTheObservedVertexOrder) {
  const std::vector<VecX> frames = { frame({ 0, 0, 0, 1, 0, 0 }) };
  observe::Observation obs;
  obs.vertex_ids = { 1, 0 };
  obs.dt = 0.1;
  Positions p(2, 3);
  p << 1, 2, 0, 0, 0, 3; // vertex 1 seen 2 m off in y, vertex 0 3 m off in z
  obs.positions = { p };
  const Eigen::MatrixXd e = vertex_errors(frames, obs);
  ASSERT_EQ(e.cols(), 2);
  EXPECT_DOUBLE_EQ(e(0, 0), 2);
  EXPECT_DOUBLE_EQ(e(0, 1), 3);
}

TEST(ErrorDistribution, MismatchedFramesAreInputErrors) {
  const std::vector<VecX> a = { frame({ 0, 0, 0 }) };
  const std::vector<VecX> b = { frame({ 0, 0, 0, 1, 1, 1 }) };
  EXPECT_THROW(vertex_errors(a, b), InputError);
  EXPECT_THROW(vertex_errors(a, a, { 1 }), InputError);
  EXPECT_THROW(vertex_errors({}, a), InputError);
}

TEST(ErrorDistribution, LogBinEdgesAreGeometric) {
  const auto edges = log_bin_edges(1e-4, 1e-1, 3);
  ASSERT_EQ(edges.size(), 4u);
  EXPECT_DOUBLE_EQ(edges.front(), 1e-4);
  EXPECT_DOUBLE_EQ(edges.back(), 1e-1);
  EXPECT_NEAR(edges[1], 1e-3, 1e-15);
  EXPECT_NEAR(edges[2], 1e-2, 1e-14);
  EXPECT_THROW(log_bin_edges(0, 1, 3), InputError);
  EXPECT_THROW(log_bin_edges(1, 1, 3), InputError);
  EXPECT_THROW(log_bin_edges(1e-3, 1, 0), InputError);
}

TEST(ErrorDistribution, HistogramCountsEveryValueOnce) {
  const std::vector<double> edges = { 1, 10, 100 };
  // Below the first edge and above the last are clamped into the end bins; an edge value belongs
  // to the bin it opens.
  const std::vector<double> values = { 0.5, 1, 9.99, 10, 50, 100, 1e6 };
  const auto counts = histogram_counts(values, edges);
  ASSERT_EQ(counts.size(), 2u);
  EXPECT_EQ(counts[0], 3);
  EXPECT_EQ(counts[1], 4);
  EXPECT_EQ(std::accumulate(counts.begin(), counts.end(), 0L), long(values.size()));
  const std::vector<double> decreasing = { 2, 1 };
  EXPECT_THROW(histogram_counts(values, decreasing), InputError);
}

} // namespace
} // namespace elastolearn::learn
