// The report's animation: the surface of a box bar, frames decimated to the budget by the
// smallest stride that meets it, positions stored as little-endian float32 in base64.
#include "io_test_util.hpp"

#include <elastolearn/core/base64.hpp>
#include <elastolearn/io/report_animation.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <gtest/gtest.h>

#include <set>

namespace elastolearn::io {
namespace {

/// `count` frames of `mesh`, frame t moved by t in x.
std::vector<VecX> moving_frames(const mesh::TetMesh& mesh, int count) {
  std::vector<VecX> frames;
  for (int t = 0; t < count; ++t) {
    Positions p = mesh.rest_positions();
    p.col(0).array() += t;
    frames.push_back(Eigen::Map<const VecX>(p.data(), p.size()));
  }
  return frames;
}

TEST(ReportAnimation, ShowsTheSurfaceEveryStrideThFrame) {
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(1, 0.2, 0.2), { 4, 1, 1 });
  const std::vector<VecX> a = moving_frames(bar, 10);
  const std::vector<VecX> b = moving_frames(bar, 12); // the shorter run limits the frames
  AnimationBudget budget;
  budget.max_frames = 4;
  const SurfaceAnimation anim
      = surface_animation(bar, 0.01, { { "truth", &a }, { "learned", &b } }, nullptr, "", budget)
            .value();
  EXPECT_EQ(anim.stride, 3); // 10 frames in at most 4: 0, 3, 6, 9
  EXPECT_EQ(anim.frames, 4);
  EXPECT_DOUBLE_EQ(anim.frame_seconds, 0.03);
  const int surface = static_cast<int>(bar.surface_vertices().size());
  ASSERT_EQ(anim.tracks.size(), 2u);
  EXPECT_EQ(anim.tracks[0].count, surface);
  ASSERT_EQ(anim.tracks[0].positions.size(), std::size_t(4 * surface * 3));
  // Shown frame 2 is simulated frame 6: x moved by 6.
  const int v = bar.surface_vertices()[0];
  EXPECT_FLOAT_EQ(anim.tracks[1].positions[std::size_t(2 * surface * 3)],
      static_cast<float>(bar.rest_positions()(v, 0) + 6));
  // Every boundary triangle, re-indexed into the surface vertices.
  EXPECT_EQ(anim.faces.size(), std::size_t(3 * bar.surface_faces().rows()));
  EXPECT_EQ(std::set<int>(anim.faces.begin(), anim.faces.end()).size(), std::size_t(surface));
  EXPECT_GE(*std::min_element(anim.faces.begin(), anim.faces.end()), 0);
  EXPECT_LT(*std::max_element(anim.faces.begin(), anim.faces.end()), surface);
}

TEST(ReportAnimation, TheValueBudgetLimitsTheFramesToo) {
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(1, 0.2, 0.2), { 4, 1, 1 });
  const std::vector<VecX> a = moving_frames(bar, 100);
  const long per_frame = 3L * long(bar.surface_vertices().size());
  AnimationBudget budget;
  budget.max_values = 10 * per_frame; // at most 10 frames
  const SurfaceAnimation anim
      = surface_animation(bar, 0.01, { { "truth", &a } }, nullptr, "", budget).value();
  EXPECT_EQ(anim.stride, 10);
  EXPECT_EQ(anim.frames, 10);
  budget.max_values = per_frame; // not even two frames: no animation
  EXPECT_FALSE(surface_animation(bar, 0.01, { { "truth", &a } }, nullptr, "", budget));
}

TEST(ReportAnimation, MarkersAndJson) {
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(1, 0.2, 0.2), { 2, 1, 1 });
  const std::vector<VecX> a = moving_frames(bar, 2);
  Positions marker(1, 3);
  marker << 1, 0, 0; // float32 1.0 = 00 00 80 3F
  const std::vector<Positions> markers = { marker, marker };
  const SurfaceAnimation anim
      = surface_animation(bar, 0.5, { { "truth", &a } }, &markers, "seen").value();
  ASSERT_EQ(anim.tracks.size(), 2u);
  EXPECT_TRUE(anim.tracks[1].points);
  const nlohmann::json j = animation_to_json(anim);
  EXPECT_EQ(j.at("tracks")[1].at("label"), "seen");
  // Two frames of one point: (1, 0, 0) twice, as little-endian float32.
  EXPECT_EQ(j.at("tracks")[1].at("positions"), "AACAPwAAAAAAAAAAAACAPwAAAAAAAAAA");
  EXPECT_EQ(j.at("frames"), 2);
  const std::vector<VecX> none;
  test::expect_input_error(
      [&] {
        surface_animation(bar, 0.5, { { "empty", &none } });
      },
      { "empty", "no frames" });
}

} // namespace
} // namespace elastolearn::io
