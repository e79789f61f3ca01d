// Visible-vertex selection spreads over the surface and is deterministic; observe_vertices() copies
// the right vertices and adds seeded Gaussian noise of the requested size.
#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/observe/visible_vertices.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

using namespace elastolearn;
using namespace elastolearn::observe;

namespace {

double min_pairwise_distance(const Positions& x, const std::vector<int>& ids) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < ids.size(); ++a) {
    for (std::size_t b = a + 1; b < ids.size(); ++b)
      best = std::min(best, (x.row(ids[a]) - x.row(ids[b])).norm());
  }
  return best;
}

/// Largest distance from any surface vertex to its nearest selected vertex (the covering radius).
double covering_radius(const mesh::TetMesh& m, const std::vector<int>& ids) {
  const Positions& x = m.rest_positions();
  double worst = 0;
  for (int v : m.surface_vertices()) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int id : ids)
      nearest = std::min(nearest, (x.row(v) - x.row(id)).norm());
    worst = std::max(worst, nearest);
  }
  return worst;
}

/// A frame sequence whose values identify vertex and frame: x(v, c) = v + 0.1 c + 100 t.
std::vector<Positions> labelled_frames(int n, int frames) {
  std::vector<Positions> out;
  for (int t = 0; t < frames; ++t) {
    Positions x(n, 3);
    for (int v = 0; v < n; ++v)
      x.row(v) << v + 100.0 * t, v + 0.1 + 100.0 * t, v + 0.2 + 100.0 * t;
    out.push_back(x);
  }
  return out;
}

} // namespace

TEST(VisibleVertices, SpreadOverTheSurfaceNotClustered) {
  const mesh::TetMesh sphere = mesh::make_sphere(1.0, 3000);
  const auto& surface = sphere.surface_vertices();
  const std::vector<int> ids = select_visible_vertices(sphere, 0.13, 7);
  ASSERT_EQ(int(ids.size()), int(std::lround(0.13 * surface.size())));
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  EXPECT_EQ(std::set<int>(ids.begin(), ids.end()).size(), ids.size());
  for (int id : ids)
    EXPECT_TRUE(std::binary_search(surface.begin(), surface.end(), id)) << id;

  // A clustered pick of the same size: the surface vertices nearest to one of them.
  const Positions& x = sphere.rest_positions();
  std::vector<int> clustered = surface;
  const Vec3 pole = x.row(ids.front()).transpose();
  std::sort(clustered.begin(), clustered.end(), [&](int a, int b) {
    return (x.row(a).transpose() - pole).norm() < (x.row(b).transpose() - pole).norm();
  });
  clustered.resize(ids.size());

  // Farthest-point sampling keeps neighbours well apart and leaves no region uncovered: for N = 50
  // points spread on a unit sphere the spacing is ~ √(4π/N) ≈ 0.5; a cap of the same number of
  // mesh vertices is packed at the mesh spacing and leaves the far side ~2 m away.
  // Measured: min distance 0.34 (spread) vs 0.13 (cap); covering radius 0.34 vs 1.88.
  const double spread_min = min_pairwise_distance(x, ids);
  const double clustered_min = min_pairwise_distance(x, clustered);
  EXPECT_GT(spread_min, 2.0 * clustered_min);
  EXPECT_GT(spread_min, 0.5 * std::sqrt(4 * M_PI / ids.size()));
  EXPECT_LT(covering_radius(sphere, ids), 0.5);
  EXPECT_GT(covering_radius(sphere, clustered), 1.5);
}

TEST(VisibleVertices, DeterministicForASeedAndSeedDependent) {
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(4, 1, 1), { 16, 4, 4 });
  const auto a = select_visible_vertices(bar, 0.06, 42);
  const auto b = select_visible_vertices(bar, 0.06, 42);
  EXPECT_EQ(a, b);
  bool any_differs = false;
  for (std::uint64_t seed = 1; seed < 6; ++seed)
    any_differs = any_differs || select_visible_vertices(bar, 0.06, seed) != a;
  EXPECT_TRUE(any_differs); // the seed picks the first vertex
}

TEST(VisibleVertices, FullFractionIsEverySurfaceVertex) {
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(2, 1, 1), { 4, 2, 2 });
  EXPECT_EQ(select_visible_vertices(bar, 1.0, 3), bar.surface_vertices());
  EXPECT_EQ(visible_vertex_count(1e-6, 50), 1); // never zero vertices
}

TEST(VisibleVertices, RejectsBadFractionsAndCounts) {
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(2, 1, 1), { 4, 2, 2 });
  for (double f : { 0.0, -0.1, 1.5, std::nan("") })
    EXPECT_THROW(select_visible_vertices(bar, f, 1), InputError) << f;
  EXPECT_THROW(farthest_point_sample(bar.rest_positions(), { 0, 1 }, 3, 1), InputError);
  EXPECT_THROW(farthest_point_sample(bar.rest_positions(), { 0, 999 }, 1, 1), InputError);
}

TEST(Observe, CopiesTheObservedVerticesOfEveryFrame) {
  const auto frames = labelled_frames(10, 4);
  const std::vector<int> ids { 7, 2, 5 };
  const Observation obs = observe_vertices(frames, 0.01, ids, 0.0, 1, 0.5);
  ASSERT_EQ(obs.num_frames(), 4);
  EXPECT_EQ(obs.vertex_ids, ids);
  EXPECT_EQ(obs.dt, 0.01);
  EXPECT_EQ(obs.start_time, 0.5);
  for (int t = 0; t < 4; ++t) {
    for (int j = 0; j < 3; ++j)
      EXPECT_EQ(obs.positions[t].row(j), frames[t].row(ids[j])) << t << " " << j;
  }
}

TEST(Observe, NoiseIsSeededGaussianOfTheRequestedSize) {
  const auto frames = labelled_frames(200, 50);
  std::vector<int> ids(200);
  for (int i = 0; i < 200; ++i)
    ids[i] = i;
  const double sigma = 2e-3;
  const Observation a = observe_vertices(frames, 0.01, ids, sigma, 9);
  const Observation b = observe_vertices(frames, 0.01, ids, sigma, 9);
  const Observation c = observe_vertices(frames, 0.01, ids, sigma, 10);
  double sum = 0, sum2 = 0;
  int count = 0;
  for (int t = 0; t < 50; ++t) {
    EXPECT_EQ(a.positions[t], b.positions[t]);
    EXPECT_NE(a.positions[t], c.positions[t]);
    const Positions e = a.positions[t] - frames[t];
    sum += e.sum();
    sum2 += e.squaredNorm();
    count += int(e.size());
  }
  // 30 000 draws: the sample mean has std σ/√N ≈ 0.006σ, the sample std deviates by ~0.4 %.
  const double mean = sum / count;
  const double std = std::sqrt(sum2 / count - mean * mean);
  EXPECT_LT(std::abs(mean), 0.03 * sigma);
  EXPECT_NEAR(std, sigma, 0.02 * sigma);
}

TEST(Observe, RejectsBadInput) {
  const auto frames = labelled_frames(5, 2);
  EXPECT_THROW(observe_vertices(frames, 0.01, { 1, 5 }, 0.0, 1), InputError); // out of range
  EXPECT_THROW(observe_vertices(frames, 0.01, { 1, 1 }, 0.0, 1), InputError); // duplicate
  EXPECT_THROW(observe_vertices(frames, 0.01, { 1 }, -1.0, 1), InputError); // negative noise
  EXPECT_THROW(observe_vertices(frames, 0.0, { 1 }, 0.0, 1), InputError); // dt
  EXPECT_THROW(observe_vertices({}, 0.01, { 1 }, 0.0, 1), InputError); // no frames
}
