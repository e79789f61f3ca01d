// Readers of tet-mesh files: fixtures read correctly, TetGen round-trips exactly, and every
// reader rejects truncated files, bad indices, NaN coordinates and degenerate/inverted tets with
// an InputError that names the file (and the line where that is meaningful).
#include "mesh_test_util.hpp"

#include <elastolearn/mesh/gmsh_io.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/read_tet_mesh.hpp>
#include <elastolearn/mesh/tetgen_io.hpp>
#include <elastolearn/mesh/vega_io.hpp>

using namespace elastolearn;
using namespace elastolearn::mesh;

namespace {

/// The fixtures all hold the same two tets: (0,1,2,3) and (1,2,3,4) with x4 = (1,1,1).
void expect_two_tets(const TetMesh& m) {
  ASSERT_EQ(m.num_vertices(), 5);
  ASSERT_EQ(m.num_tets(), 2);
  EXPECT_EQ(m.tets().row(0), Eigen::RowVector4i(0, 1, 2, 3));
  EXPECT_EQ(m.tets().row(1), Eigen::RowVector4i(1, 2, 3, 4));
  EXPECT_EQ(Vec3(m.rest_positions().row(4)), Vec3(1, 1, 1));
  EXPECT_NEAR(m.total_volume(), 0.5, 1e-15);
  EXPECT_EQ(m.surface_faces().rows(), 6); // the shared face is interior
}

} // namespace

TEST(TetgenIo, ReadsOneBasedFileWithAttributesMarkersAndComments) {
  expect_two_tets(read_tetgen(test::fixture("two_tets")));
  expect_two_tets(read_tet_mesh(test::fixture("two_tets.node")));
  expect_two_tets(read_tet_mesh(test::fixture("two_tets.ele")));
}

TEST(TetgenIo, WriteThenReadIsIdentical) {
  test::TempDir dir;
  // Irrational-looking coordinates: the writer must print them losslessly.
  const TetMesh original = make_sphere(0.1234567, 300);
  write_tetgen(dir / "ball", original);
  EXPECT_TRUE(std::filesystem::exists(dir / "ball.node"));
  EXPECT_TRUE(std::filesystem::exists(dir / "ball.ele"));
  const TetMesh back = read_tet_mesh(dir / "ball.node");
  EXPECT_EQ(back.rest_positions(), original.rest_positions()); // bitwise equal
  EXPECT_EQ(back.tets(), original.tets());
  EXPECT_EQ(back.surface_faces(), original.surface_faces());
  // Writing over an existing mesh leaves no temporary files behind.
  write_tetgen(dir / "ball.ele", make_box_bar(Vec3(1, 1, 1), { 1, 1, 1 }));
  EXPECT_EQ(read_tetgen(dir / "ball").num_tets(), 6);
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 2);
}

TEST(TetgenIo, ZeroBasedAndTenNodeTets) {
  test::TempDir dir;
  test::write_file(dir / "z.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
  test::write_file(dir / "z.ele", "1 10 0\n0 0 1 2 3 0 1 2 3 0 1\n");
  const TetMesh m = read_tetgen(dir / "z");
  EXPECT_EQ(m.tets().row(0), Eigen::RowVector4i(0, 1, 2, 3));
}

TEST(GmshIo, ReadsVersion2WithNonContiguousTagsAndOtherElements) {
  expect_two_tets(read_gmsh(test::fixture("two_tets_v2.msh"))); // node 99 is dropped (unused)
}

TEST(GmshIo, ReadsVersion41WithEntityBlocks) {
  expect_two_tets(read_tet_mesh(test::fixture("two_tets_v4.msh"))); // node 60 is dropped
}

TEST(GmshIo, RejectsBinaryAndUnsupportedVersions) {
  test::TempDir dir;
  const std::string v2 = test::read_fixture("two_tets_v2.msh");
  test::write_file(dir / "b.msh", test::replaced(v2, "2.2 0 8", "2.2 1 8"));
  test::expect_input_error([&] { read_gmsh(dir / "b.msh"); }, { "b.msh:2", "binary" });
  test::write_file(dir / "v3.msh", test::replaced(v2, "2.2 0 8", "3.0 0 8"));
  test::expect_input_error([&] { read_gmsh(dir / "v3.msh"); }, { "v3.msh:2", "version 3.0" });
}

TEST(VegaIo, ReadsTetSectionIgnoringMaterials) {
  expect_two_tets(read_vega(test::fixture("two_tets.veg")));
  expect_two_tets(read_tet_mesh(test::fixture("two_tets.veg")));
}

TEST(ReadTetMesh, RejectsUnknownExtensionAndMissingFile) {
  test::expect_input_error([] { read_tet_mesh("mesh.vtk"); }, { "mesh.vtk", "unknown" });
  test::expect_input_error([] { read_tet_mesh("/nonexistent/m.veg"); }, { "/nonexistent/m.veg" });
}

// ---- every reader rejects bad files ---------------------------------------------------------

namespace {

struct BadFile {
  std::string name; ///< test name
  std::string fixture; ///< fixture file to corrupt
  std::string from, to; ///< the corruption (first occurrence replaced)
  std::string read_as; ///< file name to write and read (its extension picks the reader)
  std::vector<std::string> expect; ///< fragments the message must contain (besides the file)
};

std::ostream& operator<<(std::ostream& os, const BadFile& b) {
  return os << b.name;
}

class RejectsBadFile : public testing::TestWithParam<BadFile> { };

} // namespace

TEST_P(RejectsBadFile, WithClearErrorNamingFile) {
  const BadFile& bad = GetParam();
  test::TempDir dir;
  // TetGen needs both files; copy the untouched partner first.
  for (const char* partner : { "two_tets.node", "two_tets.ele" })
    if (bad.fixture.starts_with("two_tets.") && bad.read_as.starts_with("two_tets."))
      test::write_file(dir / partner, test::read_fixture(partner));
  test::write_file(
      dir / bad.read_as, test::replaced(test::read_fixture(bad.fixture), bad.from, bad.to));
  std::vector<std::string> fragments = bad.expect;
  fragments.push_back(dir.path().string()); // the full path of the file (listed in `expect`)
  try {
    read_tet_mesh(dir / bad.read_as);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    for (const auto& f : fragments)
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos)
          << "message: " << e.what() << "\nlacks: " << f;
  }
}

INSTANTIATE_TEST_SUITE_P(Readers, RejectsBadFile,
    testing::Values(
        // TetGen
        BadFile { "tetgen_truncated_node", "two_tets.node", "5 1 1 1 0.5 0\n", "", "two_tets.node",
            { "two_tets.node:", "end of file", "point 4 of 5" } },
        BadFile { "tetgen_truncated_ele", "two_tets.ele", "2 2 3 4 5 7\n", "", "two_tets.ele",
            { "two_tets.ele:", "end of file", "tetrahedron 1 of 2" } },
        BadFile { "tetgen_bad_index", "two_tets.ele", "2 2 3 4 5 7", "2 2 3 4 6 7", "two_tets.ele",
            { "two_tets.ele:4", "index 6", "out of range" } },
        BadFile { "tetgen_not_a_number", "two_tets.ele", "2 2 3 4 5 7", "2 2 x 4 5 7",
            "two_tets.ele", { "two_tets.ele:4", "invalid integer 'x'" } },
        BadFile { "tetgen_nan", "two_tets.node", "5 1 1 1", "5 1 nan 1", "two_tets.node",
            { "two_tets.node:8", "non-finite", "nan" } },
        BadFile { "tetgen_inverted", "two_tets.ele", "1 1 2 3 4 7", "1 2 1 3 4 7", "two_tets.ele",
            { "two_tets.ele:3", "tet 0", "inverted" } },
        BadFile { "tetgen_degenerate", "two_tets.node", "5 1 1 1", "5 0.5 0.5 0", "two_tets.node",
            { "two_tets.ele:4", "tet 1", "degenerate" } },
        // Gmsh v2
        BadFile { "gmsh2_truncated", "two_tets_v2.msh", "4 4 2 1 1 20 30 40 50\n$EndElements\n", "",
            "a.msh", { "a.msh:", "end of file" } },
        BadFile { "gmsh2_bad_index", "two_tets_v2.msh", "1 20 30 40 50", "1 20 30 40 55", "a.msh",
            { "a.msh:22", "unknown node tag 55" } },
        BadFile { "gmsh2_nan", "two_tets_v2.msh", "50 1 1 1", "50 1 NaN 1", "a.msh",
            { "a.msh:14", "non-finite" } },
        BadFile { "gmsh2_inverted", "two_tets_v2.msh", "1 10 20 30 40", "1 20 10 30 40", "a.msh",
            { "a.msh:21", "tet 0", "inverted" } },
        BadFile { "gmsh2_degenerate", "two_tets_v2.msh", "50 1 1 1", "50 0.25 0.25 0.5", "a.msh",
            { "a.msh:22", "tet 1", "degenerate" } },
        // Gmsh v4.1
        BadFile { "gmsh4_truncated", "two_tets_v4.msh", "3 20 30 40 50\n$EndElements\n", "",
            "b.msh", { "b.msh:", "end of file" } },
        BadFile { "gmsh4_bad_index", "two_tets_v4.msh", "3 20 30 40 50", "3 20 30 40 7", "b.msh",
            { "b.msh:32", "unknown node tag 7" } },
        BadFile { "gmsh4_nan", "two_tets_v4.msh", "0 0 1\n", "0 nan 1\n", "b.msh",
            { "b.msh:22", "non-finite" } },
        BadFile { "gmsh4_inverted", "two_tets_v4.msh", "2 10 20 30 40", "2 10 30 20 40", "b.msh",
            { "b.msh:31", "tet 0", "inverted" } },
        BadFile { "gmsh4_degenerate", "two_tets_v4.msh", "1 1 1\n", "0.5 0.25 0.25\n", "b.msh",
            { "b.msh:32", "tet 1", "degenerate" } },
        // Vega
        BadFile { "vega_truncated", "two_tets.veg", "2 2 3 4 5\n", "", "c.veg",
            { "c.veg:", "truncated *ELEMENTS", "expected 2 elements, found 1" } },
        BadFile { "vega_bad_index", "two_tets.veg", "2 2 3 4 5", "2 2 3 4 6", "c.veg",
            { "c.veg:14", "vertex id 6", "out of range" } },
        BadFile { "vega_zero_index", "two_tets.veg", "1 1 2 3 4", "1 0 2 3 4", "c.veg",
            { "c.veg:13", "vertex id 0" } },
        BadFile { "vega_nan", "two_tets.veg", "5 1 1 1", "5 1 1 nan", "c.veg",
            { "c.veg:8", "non-finite" } },
        BadFile { "vega_inverted", "two_tets.veg", "2 2 3 4 5", "2 3 2 4 5", "c.veg",
            { "c.veg:14", "tet 1", "inverted" } },
        BadFile { "vega_degenerate", "two_tets.veg", "5 1 1 1", "5 0 0.5 0.5", "c.veg",
            { "c.veg:14", "tet 1", "degenerate" } },
        BadFile {
            "vega_cubic", "two_tets.veg", "TET", "CUBIC", "c.veg", { "c.veg:11", "only TET" } }),
    [](const testing::TestParamInfo<BadFile>& info) { return info.param.name; });

TEST(Examples, RealMeshExampleIsAValidTetMesh) {
  // examples/03_real_mesh: TetGen output committed to the repository (see its README).
  const TetMesh m = read_tet_mesh(
      std::filesystem::path(ELASTOLEARN_EXAMPLES_DIR) / "03_real_mesh" / "elephant.node");
  EXPECT_EQ(m.num_tets(), 2830);
  EXPECT_EQ(m.num_vertices(), 958);
  EXPECT_NEAR(
      test::divergence_volume(m.rest_positions(), m.surface_faces()), m.total_volume(), 1e-12);
  EXPECT_EQ(m.quality().num_degenerate, 0);
}
