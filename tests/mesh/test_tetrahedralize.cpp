// Tetrahedralization through the external TetGen program, on procedural closed surfaces.
// Skipped when TetGen is not installed.
#include "mesh_test_util.hpp"

#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/surface_mesh.hpp>
#include <elastolearn/mesh/tetrahedralize.hpp>

using namespace elastolearn;
using namespace elastolearn::mesh;

namespace {

SurfaceMesh sphere_surface(int target_tets) {
  const TetMesh ball = make_sphere(1.0, target_tets);
  return remove_unreferenced_vertices({ ball.rest_positions(), ball.surface_faces() });
}

#define REQUIRE_TETGEN()                                                                           \
  if (!tetgen_available())                                                                         \
  GTEST_SKIP() << "TetGen program not found: " << tetgen_executable()

} // namespace

TEST(Tetrahedralize, FillsTheSurfaceExactly) {
  REQUIRE_TETGEN();
  const SurfaceMesh surface = sphere_surface(750);
  TetrahedralizeReport report;
  const TetMesh m = tetrahedralize(surface, {}, &report);
  EXPECT_EQ(report.num_tets, m.num_tets());
  EXPECT_EQ(report.runs.size(), 1u);
  EXPECT_FALSE(report.simplified);
  // TetGen keeps the input polyhedron (it may only split its faces), so the tets fill exactly
  // the enclosed volume, up to rounding.
  EXPECT_NEAR(m.total_volume(), enclosed_volume(surface), 1e-9);
  EXPECT_NEAR(
      test::divergence_volume(m.rest_positions(), m.surface_faces()), m.total_volume(), 1e-12);
  EXPECT_EQ(m.quality().num_degenerate, 0);
}

TEST(Tetrahedralize, LandsNearTheTargetCountWithoutExceedingIt) {
  REQUIRE_TETGEN();
  const SurfaceMesh surface = sphere_surface(750); // 288 faces: coarse enough for 5000 tets
  TetrahedralizeOptions options;
  options.max_tets = 5000;
  TetrahedralizeReport report;
  const TetMesh m = tetrahedralize(surface, options, &report);
  std::printf("target 5000: %d tets after %zu TetGen runs (%.2f s)\n", m.num_tets(),
      report.runs.size(), report.seconds);
  EXPECT_LE(m.num_tets(), 5500); // at most 10 % over
  EXPECT_GE(m.num_tets(), 4000); // and not far below
  EXPECT_FALSE(report.simplified);
  EXPECT_GT(report.max_volume, 0); // reached by bounding the volume
  EXPECT_NEAR(m.total_volume(), enclosed_volume(surface), 1e-9);
}

TEST(Tetrahedralize, SimplifiesASurfaceTooFineForTheTarget) {
  REQUIRE_TETGEN();
  const SurfaceMesh surface = sphere_surface(20000); // ~3900 faces need ≫ 600 tets
  TetrahedralizeOptions options;
  options.max_tets = 600;
  TetrahedralizeReport report;
  const TetMesh m = tetrahedralize(surface, options, &report);
  EXPECT_TRUE(report.simplified);
  EXPECT_LT(report.surface_faces, report.input_faces);
  EXPECT_LE(m.num_tets(), 660);
  // The simplified sphere still holds most of the volume (QEM keeps vertices on the sphere).
  EXPECT_NEAR(m.total_volume(), enclosed_volume(surface), 0.1 * enclosed_volume(surface));
}

TEST(Tetrahedralize, ClearErrors) {
  TetrahedralizeOptions bad;
  bad.min_radius_edge_ratio = 0.5;
  test::expect_input_error([&] { bad.validate(); }, { "min_radius_edge_ratio", "0.5" });
  bad = {};
  bad.max_tets = -3;
  test::expect_input_error([&] { bad.validate(); }, { "max_tets" });

  SurfaceMesh open = sphere_surface(750);
  open.faces.conservativeResize(open.faces.rows() - 1, 3);
  test::expect_input_error([&] { tetrahedralize(open, {}, nullptr, "open.off"); },
      { "open.off", "not closed", "3 edges belong to one face" });

  TetrahedralizeOptions missing;
  missing.tetgen_executable = "/nonexistent/tetgen";
  test::expect_input_error([&] { tetrahedralize(sphere_surface(750), missing); },
      { "/nonexistent/tetgen", "not found" });
}

TEST(Tetrahedralize, ReportsSelfIntersectingSurface) {
  REQUIRE_TETGEN();
  // Two overlapping balls in one surface: closed, but the surfaces cross each other.
  const SurfaceMesh a = sphere_surface(300);
  SurfaceMesh both;
  both.vertices.resize(2 * a.vertices.rows(), 3);
  both.vertices << a.vertices, (a.vertices.rowwise() + Eigen::RowVector3d(0.5, 0.1, 0.05));
  both.faces.resize(2 * a.faces.rows(), 3);
  both.faces << a.faces, (a.faces.array() + static_cast<int>(a.vertices.rows())).matrix();
  test::expect_input_error([&] { tetrahedralize(both, {}, nullptr, "two_balls.off"); },
      { "two_balls.off", "intersecting faces" });
}
