#include "mesh_test_util.hpp"

#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>

#include <cmath>
#include <map>
#include <numbers>

using namespace elastolearn;
using namespace elastolearn::mesh;

namespace {

/// Each undirected edge of the surface appears in exactly two faces, once in each direction
/// (closed, consistently oriented, hence the tet mesh is conforming).
bool closed_and_oriented(const Faces& f) {
  std::map<std::pair<int, int>, int> directed;
  for (Eigen::Index i = 0; i < f.rows(); ++i)
    for (int k = 0; k < 3; ++k)
      ++directed[{ f(i, k), f(i, (k + 1) % 3) }];
  for (const auto& [e, n] : directed)
    if (n != 1 || directed.count({ e.second, e.first }) == 0)
      return false;
  return true;
}

} // namespace

TEST(Sphere, CountWithinThirtyPercentOfTarget) {
  for (int target : { 48, 100, 300, 500, 700, 1000, 2000, 3000, 5000, 12000 }) {
    const TetMesh m = make_sphere(1.0, target);
    EXPECT_NEAR(m.num_tets(), target, 0.3 * target) << "target " << target;
  }
}

TEST(Sphere, SurfaceOnSphereClosedOutwardAndGoodQuality) {
  const double r = 0.3;
  const TetMesh m = make_sphere(r, 3000);
  const Vec3 c = m.bounding_box().center();
  EXPECT_LT(c.norm(), 1e-15); // centred at the origin (symmetric construction)
  for (int v : m.surface_vertices())
    ASSERT_NEAR(m.rest_positions().row(v).norm(), r, 1e-15) << "vertex " << v;
  EXPECT_TRUE(closed_and_oriented(m.surface_faces()));
  // The divergence theorem over the outward surface must reproduce the tet volume sum.
  EXPECT_NEAR(
      test::divergence_volume(m.rest_positions(), m.surface_faces()), m.total_volume(), 1e-14);
  const MeshQuality q = m.quality();
  RecordProperty("min_dihedral_deg", std::to_string(q.min_dihedral_deg));
  RecordProperty("max_radius_ratio", std::to_string(q.max_radius_ratio));
  std::printf(
      "sphere %d tets: min dihedral %.2f deg, max dihedral %.2f deg, max radius ratio %.2f\n",
      m.num_tets(), q.min_dihedral_deg, q.max_dihedral_deg, q.max_radius_ratio);
  EXPECT_GT(q.min_dihedral_deg, 10.0);
  EXPECT_LT(q.max_dihedral_deg, 170.0);
}

TEST(Sphere, VolumeConvergesToBallVolumeQuadratically) {
  // Inscribed polyhedron: volume below 4/3πr³, error O(h²) so ×8 tets (h/2) gives ~1/4 error.
  const double exact = 4.0 / 3.0 * std::numbers::pi;
  double previous = 1.0;
  for (int target : { 750, 6000, 48000 }) {
    const TetMesh m = make_sphere(1.0, target);
    const double err = (exact - m.total_volume()) / exact;
    EXPECT_GT(err, 0.0);
    std::printf("sphere %6d tets: relative volume error %.4f\n", m.num_tets(), err);
    if (previous < 1.0) {
      EXPECT_LT(err, 0.35 * previous);
      EXPECT_GT(err, 0.15 * previous);
    }
    previous = err;
  }
  EXPECT_LT(previous, 0.01);
}

TEST(Sphere, RejectsBadArguments) {
  test::expect_input_error([] { make_sphere(-1.0, 100); }, { "radius" });
  test::expect_input_error([] { make_sphere(1.0, 0); }, { "target_tets" });
  test::expect_input_error([] { make_box_bar(Vec3(1, 0, 1), { 1, 1, 1 }); }, { "size[1]" });
  test::expect_input_error([] { make_box_bar(Vec3(1, 1, 1), { 1, 0, 1 }); }, { "cells[1]" });
}

TEST(VertexSelection, PlanesBoxesAndExtremes) {
  const TetMesh m = make_box_bar(Vec3(4, 1, 1), { 4, 1, 1 }); // 5×2×2 lattice, unit spacing
  const auto left = vertices_with_min_coordinate(m, 0, 1e-9);
  ASSERT_EQ(left.size(), 4u);
  for (int v : left)
    EXPECT_EQ(m.rest_positions()(v, 0), 0.0);
  EXPECT_TRUE(std::is_sorted(left.begin(), left.end()));
  const auto right = vertices_with_max_coordinate(m, 0, 1e-9);
  ASSERT_EQ(right.size(), 4u);
  for (int v : right)
    EXPECT_EQ(m.rest_positions()(v, 0), 4.0);
  EXPECT_EQ(vertices_near_plane(m, 0, 2.0, 1e-9).size(), 4u);
  EXPECT_EQ(vertices_near_plane(m, 0, 2.4, 0.5).size(), 4u); // only x = 2 within 0.5
  EXPECT_EQ(vertices_near_plane(m, 0, 2.5, 0.5).size(), 8u); // x = 2 and x = 3, inclusive
  EXPECT_EQ(vertices_near_plane(m, 2, 1.0, 1e-9).size(), 10u);
  EXPECT_EQ(vertices_in_box(m, Box3(Vec3(-1, -1, -1), Vec3(1.5, 2, 2))).size(), 8u);
  EXPECT_TRUE(vertices_in_box(m, Box3(Vec3(10, 10, 10), Vec3(11, 11, 11))).empty());
  test::expect_input_error([&] { vertices_near_plane(m, 3, 0, 0); }, { "axis" });
  test::expect_input_error([&] { vertices_near_plane(m, 0, 0, -1); }, { "tolerance" });
}
