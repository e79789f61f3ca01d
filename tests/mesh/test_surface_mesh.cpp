// Surface readers (OBJ, OFF, PLY ascii/binary, STL ascii/binary) on a unit cube written in each
// format; closedness, enclosed volume, simplification; and the readers' error messages.
#include "mesh_test_util.hpp"

#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/surface_mesh.hpp>
#include <elastolearn/mesh/surface_repair.hpp>
#include <elastolearn/mesh/surface_simplification.hpp>

#include <cstdint>
#include <cstring>

using namespace elastolearn;
using namespace elastolearn::mesh;

namespace {

// Unit cube: vertex i = (i&1, i>>1&1, i>>2&1); quads counter-clockwise seen from outside.
constexpr int kQuads[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 },
  { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
Vec3 corner(int i) {
  return Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1);
}

std::string cube_obj() {
  std::string s = "# cube\nmtllib x.mtl\no cube\n";
  for (int i = 0; i < 8; ++i) {
    const Vec3 c = corner(i);
    s += "v " + std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z())
        + "\n";
  }
  s += "vt 0 0\nvn 0 0 1\n";
  for (int f = 0; f < 6; ++f) {
    s += "f";
    for (int k = 0; k < 4; ++k) {
      const int v = kQuads[f][k];
      // Mix plain, v/t/n and negative (relative) indices.
      s += ' ';
      if (f % 3 == 0)
        s += std::to_string(v + 1);
      else if (f % 3 == 1)
        s += std::to_string(v + 1) + "/1/1";
      else
        s += std::to_string(v - 8);
    }
    s += "\n";
  }
  return s;
}

std::string cube_off() {
  std::string s = "OFF\n# a comment\n8 6 0\n";
  for (int i = 0; i < 8; ++i) {
    const Vec3 c = corner(i);
    s += std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z()) + "\n";
  }
  for (const auto& q : kQuads)
    s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " "
        + std::to_string(q[3]) + "\n";
  return s;
}

std::string ply_header(const char* format) {
  return std::string("ply\nformat ") + format
      + " 1.0\ncomment cube\nelement vertex 8\nproperty float x\nproperty float y\nproperty float "
        "z\n"
        "property uchar red\nelement face 6\nproperty list uchar int vertex_indices\n"
        "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
}

std::string cube_ply_ascii() {
  std::string s = ply_header("ascii");
  for (int i = 0; i < 8; ++i) {
    const Vec3 c = corner(i);
    s += std::to_string(c.x()) + " " + std::to_string(c.y()) + " " + std::to_string(c.z())
        + " 255\n";
  }
  for (const auto& q : kQuads)
    s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " "
        + std::to_string(q[3]) + "\n";
  return s + "0 1\n";
}

template <typename T> void put(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T)); // this test assumes a little-endian host (x86, arm64)
  s.append(b, sizeof(T));
}

std::string cube_ply_binary() {
  std::string s = ply_header("binary_little_endian");
  for (int i = 0; i < 8; ++i) {
    const Vec3 c = corner(i);
    for (int k = 0; k < 3; ++k)
      put(s, static_cast<float>(c[k]));
    put(s, std::uint8_t { 200 });
  }
  for (const auto& q : kQuads) {
    put(s, std::uint8_t { 4 });
    for (int k = 0; k < 4; ++k)
      put(s, static_cast<std::int32_t>(q[k]));
  }
  put(s, std::int32_t { 0 });
  put(s, std::int32_t { 1 });
  return s;
}

std::string cube_stl_ascii() {
  std::string s = "solid cube\n";
  for (const auto& q : kQuads)
    for (int t = 0; t < 2; ++t) {
      s += "  facet normal 0 0 0\n    outer loop\n";
      for (int k : { 0, t + 1, t + 2 }) {
        const Vec3 c = corner(q[k]);
        s += "      vertex " + std::to_string(c.x()) + " " + std::to_string(c.y()) + " "
            + std::to_string(c.z()) + "\n";
      }
      s += "    endloop\n  endfacet\n";
    }
  return s + "endsolid cube\n";
}

std::string cube_stl_binary() {
  std::string s = "solid but actually binary";
  s.resize(80, ' ');
  put(s, std::uint32_t { 12 });
  for (const auto& q : kQuads)
    for (int t = 0; t < 2; ++t) {
      for (int k = 0; k < 3; ++k)
        put(s, 0.0f);
      for (int k : { 0, t + 1, t + 2 })
        for (int a = 0; a < 3; ++a)
          put(s, static_cast<float>(corner(q[k])[a]));
      put(s, std::uint16_t { 0 });
    }
  return s;
}

void expect_unit_cube(const SurfaceMesh& s) {
  EXPECT_EQ(s.vertices.rows(), 8);
  EXPECT_EQ(s.faces.rows(), 12); // 6 quads, fan-triangulated
  EXPECT_TRUE(is_closed(s));
  EXPECT_NEAR(enclosed_volume(s), 1.0, 1e-12); // outward orientation preserved
}

} // namespace

TEST(SurfaceMesh, ReadsCubeInEveryFormat) {
  test::TempDir dir;
  const std::pair<const char*, std::string> files[] = { { "c.obj", cube_obj() },
    { "c.off", cube_off() }, { "c.ply", cube_ply_ascii() }, { "b.PLY", cube_ply_binary() },
    { "c.stl", cube_stl_ascii() }, { "b.stl", cube_stl_binary() } };
  for (const auto& [name, text] : files) {
    SCOPED_TRACE(name);
    test::write_file(dir / name, text);
    expect_unit_cube(read_surface_mesh(dir / name));
  }
}

TEST(SurfaceMesh, OpenSurfaceIsNotClosedAndOffRoundTrips) {
  test::TempDir dir;
  test::write_file(dir / "c.off", cube_off());
  SurfaceMesh s = read_surface_mesh(dir / "c.off");
  write_off(dir / "copy.off", s);
  const SurfaceMesh back = read_surface_mesh(dir / "copy.off");
  EXPECT_EQ(back.vertices, s.vertices);
  EXPECT_EQ(back.faces, s.faces);
  s.faces.conservativeResize(11, 3);
  EXPECT_FALSE(is_closed(s));
  EXPECT_EQ(edge_defects(s).boundary_edges, 3);
}

TEST(SurfaceMesh, FillHolesClosesTriangleAndQuadHoles) {
  test::TempDir dir;
  test::write_file(dir / "c.off", cube_off());
  const SurfaceMesh cube = read_surface_mesh(dir / "c.off");
  for (int removed : { 1, 2 }) { // one triangle (3-edge hole) or a whole side (4-edge hole)
    SurfaceMesh open = cube;
    open.faces.conservativeResize(12 - removed, 3);
    ASSERT_FALSE(is_closed(open));
    int holes = 0;
    const SurfaceMesh closed = fill_holes(open, &holes);
    EXPECT_EQ(holes, 1);
    EXPECT_TRUE(is_closed(closed));
    // The patch lies in the plane of the missing side and is oriented like its neighbours.
    EXPECT_NEAR(enclosed_volume(closed), 1.0, 1e-12) << removed;
  }
}

TEST(SurfaceMesh, SimplifyKeepsSphereClosedAndItsVolume) {
  const TetMesh ball = make_sphere(1.0, 6000);
  const SurfaceMesh fine { ball.rest_positions(), ball.surface_faces() };
  const SurfaceMesh coarse = simplify_surface(fine, 200);
  EXPECT_LE(coarse.faces.rows(), 200);
  EXPECT_GE(coarse.faces.rows(), 150); // the sphere is smooth: nothing should block collapses
  EXPECT_TRUE(is_closed(coarse));
  // QEM keeps vertices near the sphere; 200 faces lose a few % of the volume at most.
  EXPECT_NEAR(enclosed_volume(coarse), enclosed_volume(fine), 0.05 * enclosed_volume(fine));
}

namespace {

struct BadSurface {
  std::string name, file, text;
  std::vector<std::string> expect;
};
std::ostream& operator<<(std::ostream& os, const BadSurface& b) {
  return os << b.name;
}
class RejectsBadSurface : public testing::TestWithParam<BadSurface> { };

std::vector<BadSurface> bad_surfaces() {
  const std::string off = cube_off(), obj = cube_obj(), ply = cube_ply_ascii();
  const std::string pbin = cube_ply_binary(), sbin = cube_stl_binary(), sasc = cube_stl_ascii();
  return {
    { "off_truncated", "t.off", off.substr(0, off.rfind("4 1 3")),
        { "t.off:", "end of file", "face 5 of 6" } },
    { "off_bad_index", "t.off", test::replaced(off, "4 1 3 7 5", "4 1 3 7 8"),
        { "t.off:17", "index 8", "out of range" } },
    { "off_nan", "t.off", test::replaced(off, "1.000000 1.000000 1.000000", "1 nan 1"),
        { "t.off:11", "non-finite" } },
    { "off_bad_header", "t.off", "PFF\n", { "t.off:1", "not an OFF" } },
    { "obj_bad_index", "t.obj", obj + "f 1 2 9\n", { "t.obj:", "index 8", "out of range" } },
    { "obj_nan", "t.obj", test::replaced(obj, "v 1.000000 0.000000 0.000000", "v 1 NaN 0"),
        { "t.obj:5", "non-finite" } },
    { "ply_truncated_ascii", "t.ply", ply.substr(0, ply.find("4 0 2 3 1")),
        { "t.ply:", "end of file", "face 0 of 6" } },
    { "ply_truncated_binary", "t.ply", pbin.substr(0, pbin.size() - 20),
        { "t.ply", "truncated binary", "face 5 of 6" } },
    { "ply_bad_index", "t.ply", test::replaced(ply, "4 1 3 7 5", "4 1 3 7 -1"),
        { "t.ply:", "index -1" } },
    { "ply_nan", "t.ply", test::replaced(ply, "1.000000 1.000000 1.000000 255", "1 1 nan 255"),
        { "t.ply:", "non-finite z" } },
    { "ply_big_endian", "t.ply", test::replaced(ply, "ascii", "binary_big_endian"),
        { "t.ply:2", "binary_big_endian" } },
    { "stl_truncated_binary", "t.stl", sbin.substr(0, sbin.size() - 7),
        { "t.stl", "12 triangles", "truncated" } },
    { "stl_truncated_ascii", "t.stl", sasc.substr(0, sasc.size() / 2),
        { "t.stl:", "end of file", "endsolid" } },
    { "stl_nan", "t.stl",
        test::replaced(sasc, "vertex 0.000000 0.000000 0.000000", "vertex 0 0 nan"),
        { "t.stl:4", "non-finite" } },
    { "unknown_extension", "t.vtk", off, { "t.vtk", "unknown surface-mesh extension" } },
  };
}

} // namespace

TEST_P(RejectsBadSurface, WithClearErrorNamingFile) {
  const BadSurface& bad = GetParam();
  test::TempDir dir;
  test::write_file(dir / bad.file, bad.text);
  try {
    read_surface_mesh(dir / bad.file);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.path().string()), std::string::npos) << e.what();
    for (const auto& f : bad.expect)
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos)
          << "message: " << e.what() << "\nlacks: " << f;
  }
}

INSTANTIATE_TEST_SUITE_P(Readers, RejectsBadSurface, testing::ValuesIn(bad_surfaces()),
    [](const testing::TestParamInfo<BadSurface>& info) { return info.param.name; });
