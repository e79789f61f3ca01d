#include "mesh_test_util.hpp"

#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <numbers>

using namespace elastolearn;
using namespace elastolearn::mesh;

namespace {

TetMesh unit_tet(const Vec3& d = Vec3(0, 0, 1)) {
  Positions x(4, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, d.x(), d.y(), d.z();
  Tets t(1, 4);
  t << 0, 1, 2, 3;
  return TetMesh(x, t, "unit");
}

} // namespace

TEST(TetMesh, SingleTetVolumeSurfaceAndOrientation) {
  const TetMesh m = unit_tet();
  EXPECT_DOUBLE_EQ(m.total_volume(), 1.0 / 6.0);
  ASSERT_EQ(m.surface_faces().rows(), 4);
  EXPECT_EQ(m.surface_vertices(), (std::vector<int> { 0, 1, 2, 3 }));
  // Every face normal points away from the opposite vertex (outward).
  const Vec3 centroid = m.rest_positions().colwise().mean();
  for (Eigen::Index f = 0; f < 4; ++f) {
    const Vec3 a = m.rest_positions().row(m.surface_faces()(f, 0));
    const Vec3 b = m.rest_positions().row(m.surface_faces()(f, 1));
    const Vec3 c = m.rest_positions().row(m.surface_faces()(f, 2));
    EXPECT_GT((b - a).cross(c - a).dot((a + b + c) / 3 - centroid), 0) << "face " << f;
  }
  EXPECT_NEAR(test::divergence_volume(m.rest_positions(), m.surface_faces()), 1.0 / 6.0, 1e-15);
}

TEST(TetMesh, QualityOfRegularTet) {
  // Regular tet: dihedral angle acos(1/3) = 70.5288°, circumradius = 3·inradius.
  Positions x(4, 3);
  x << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  Tets t(1, 4);
  t << 0, 2, 1, 3; // positive orientation
  const MeshQuality q = TetMesh(x, t).quality();
  const double expected = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(q.min_dihedral_deg, expected, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, expected, 1e-9);
  EXPECT_NEAR(q.max_radius_ratio, 1.0, 1e-12);
  EXPECT_NEAR(q.min_volume, 8.0 / 3.0, 1e-12);
  EXPECT_EQ(q.num_degenerate, 0);
}

TEST(TetMesh, QualityOfFlatTetIsBad) {
  // A sliver: apex barely above the base gives tiny dihedral angles and a huge radius ratio.
  const MeshQuality q = unit_tet(Vec3(0.3, 0.3, 1e-3)).quality();
  EXPECT_LT(q.min_dihedral_deg, 1.0);
  EXPECT_GT(q.max_radius_ratio, 50.0);
}

TEST(TetMesh, BoxBarVolumeSurfaceAndOutwardFaces) {
  const Vec3 size(2.0, 0.5, 0.25);
  const std::array<int, 3> cells { 8, 3, 2 };
  const TetMesh m = make_box_bar(size, cells);
  EXPECT_EQ(m.num_vertices(), 9 * 4 * 3);
  EXPECT_EQ(m.num_tets(), 6 * 8 * 3 * 2);
  const double volume = size.prod();
  // Sums of ~300 terms of size ~1e-3: relative rounding ~1e-14.
  EXPECT_NEAR(m.total_volume(), volume, 1e-13);
  EXPECT_GT(m.element_volumes().minCoeff(), 0.0);
  // Conforming: only the 2 triangles of each boundary cell face are unpaired.
  EXPECT_EQ(m.surface_faces().rows(), 4 * (8 * 3 + 3 * 2 + 2 * 8));
  EXPECT_EQ(static_cast<int>(m.surface_vertices().size()), 9 * 4 * 3 - 7 * 2 * 1);
  const double area = 2 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
  EXPECT_NEAR(test::surface_area(m.rest_positions(), m.surface_faces()), area, 1e-13);
  EXPECT_NEAR(test::divergence_volume(m.rest_positions(), m.surface_faces()), volume, 1e-13);
  // Convex box: each face normal points away from the box centre.
  const Vec3 centre = size / 2;
  for (Eigen::Index f = 0; f < m.surface_faces().rows(); ++f) {
    const Vec3 a = m.rest_positions().row(m.surface_faces()(f, 0));
    const Vec3 b = m.rest_positions().row(m.surface_faces()(f, 1));
    const Vec3 c = m.rest_positions().row(m.surface_faces()(f, 2));
    ASSERT_GT((b - a).cross(c - a).dot((a + b + c) / 3 - centre), 0) << "face " << f;
  }
  const Box3 box = m.bounding_box();
  EXPECT_TRUE(box.min().isZero());
  EXPECT_TRUE(box.max().isApprox(size));
  EXPECT_NEAR(m.bounding_box_diagonal(), size.norm(), 1e-15);
  // Kuhn tets of a cube: dihedral angles 45°, 60°, 90° (on a non-cubic cell they vary).
  const MeshQuality cube = make_box_bar(Vec3(1, 1, 1), { 2, 2, 2 }).quality();
  EXPECT_NEAR(cube.min_dihedral_deg, 45.0, 1e-9);
  EXPECT_NEAR(cube.max_dihedral_deg, 90.0, 1e-9);
}

TEST(TetMesh, RejectsEmptyMesh) {
  test::expect_input_error(
      [] { TetMesh(Positions(0, 3), Tets(0, 4), "empty.node"); }, { "empty.node", "no vertices" });
  Positions x(4, 3);
  x.setZero();
  test::expect_input_error(
      [&] { TetMesh(x, Tets(0, 4), "notets"); }, { "notets", "no tetrahedra" });
}

TEST(TetMesh, RejectsNonFiniteCoordinateNamingVertex) {
  Positions x = unit_tet().rest_positions();
  x(2, 1) = std::numeric_limits<double>::quiet_NaN();
  test::expect_input_error(
      [&] { TetMesh(x, unit_tet().tets(), "src"); }, { "src", "vertex 2", "non-finite", "nan" });
  x(2, 1) = std::numeric_limits<double>::infinity();
  test::expect_input_error([&] { TetMesh(x, unit_tet().tets(), "src"); }, { "vertex 2", "inf" });
}

TEST(TetMesh, RejectsIndexOutOfRangeNamingTet) {
  const TetMesh box = make_box_bar(Vec3(1, 1, 1), { 1, 1, 1 });
  Tets t = box.tets();
  t(4, 2) = 8;
  test::expect_input_error([&] { TetMesh(box.rest_positions(), t, "bar"); },
      { "bar", "tet 4", "index 8", "out of range" });
  t(4, 2) = -1;
  test::expect_input_error([&] { TetMesh(box.rest_positions(), t, "bar"); }, { "tet 4", "-1" });
}

TEST(TetMesh, RejectsInvertedAndDegenerateTetsWithVolume) {
  const TetMesh m = unit_tet();
  Tets t = m.tets();
  std::swap(t(0, 1), t(0, 2));
  test::expect_input_error(
      [&] { TetMesh(m.rest_positions(), t, "inv"); }, { "inv", "tet 0", "inverted", "-0.166667" });
  test::expect_input_error([&] { unit_tet(Vec3(0.5, 0.5, 0)); }, { "unit", "tet 0", "degenerate" });
  Tets repeated = m.tets();
  repeated(0, 3) = 0;
  test::expect_input_error([&] { TetMesh(m.rest_positions(), repeated, "rep"); }, { "degenerate" });
}

TEST(TetMesh, UnreferencedVerticesAreAllowed) {
  Positions x(5, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 9, 9, 9;
  Tets t(1, 4);
  t << 0, 1, 2, 3;
  const TetMesh m(x, t);
  EXPECT_EQ(m.num_vertices(), 5);
  EXPECT_EQ(m.surface_vertices(), (std::vector<int> { 0, 1, 2, 3 }));
}
