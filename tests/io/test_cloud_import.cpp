// Per-frame PLY and XYZ point clouds as scanning tools export them, and a folder of them in
// natural name order: values read back, and one clear error naming the file (and line).
#include "io_test_util.hpp"

#include <elastolearn/io/cloud_import.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

using namespace elastolearn;
using namespace elastolearn::io;
using elastolearn::io::test::expect_input_error;
using elastolearn::io::test::ScratchDir;

namespace {

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

template <typename T> void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T)); // x86: little endian
  out.append(bytes, sizeof(T));
}

} // namespace

TEST(NaturalOrder, ComparesDigitRunsAsNumbers) {
  EXPECT_TRUE(natural_less("frame_2.ply", "frame_10.ply"));
  EXPECT_FALSE(natural_less("frame_10.ply", "frame_2.ply"));
  EXPECT_TRUE(natural_less("frame_9.ply", "frame_10.ply"));
  EXPECT_TRUE(natural_less("a1b2", "a1b10"));
  EXPECT_TRUE(natural_less("a", "a1"));
  EXPECT_TRUE(natural_less("scan_0001.xyz", "scan_0002.xyz"));
  EXPECT_TRUE(natural_less("01", "1")); // total order: leading zeros break the tie
  EXPECT_FALSE(natural_less("1", "01"));
  EXPECT_FALSE(natural_less("x7", "x7"));
  EXPECT_TRUE(natural_less("18446744073709551616999", "184467440737095516169990")); // no overflow
}

TEST(PointCloudFile, ReadsXyzWithAndWithoutNormalsAndConfidence) {
  ScratchDir dir;
  write_file(dir / "a.xyz", "# exported by a scanner\n0 1 2\n3.5 -4 5e-3\n\n");
  const auto a = read_point_cloud_file(dir / "a.xyz");
  ASSERT_EQ(a.points.rows(), 2);
  EXPECT_EQ(a.points.row(1), Eigen::RowVector3d(3.5, -4, 5e-3));
  EXPECT_EQ(a.normals.rows(), 0);
  EXPECT_EQ(a.confidence.size(), 0);

  write_file(dir / "b.XYZ", "1,2,3,0,0,1,0.5\n4,5,6,0.6,0.8,0,1\n");
  const auto b = read_point_cloud_file(dir / "b.XYZ");
  ASSERT_EQ(b.points.rows(), 2);
  EXPECT_EQ(b.normals.row(1), Eigen::RowVector3d(0.6, 0.8, 0));
  EXPECT_EQ(b.confidence, Eigen::Vector2d(0.5, 1));

  write_file(dir / "c.xyz", "1 2 3 0.25\n");
  EXPECT_EQ(read_point_cloud_file(dir / "c.xyz").confidence[0], 0.25);
  write_file(dir / "empty.xyz", "# no points in this frame\n");
  EXPECT_EQ(read_point_cloud_file(dir / "empty.xyz").points.rows(), 0);
}

TEST(PointCloudFile, XyzErrorsNameTheFileAndLine) {
  ScratchDir dir;
  const auto rejected = [&](const std::string& text, const std::vector<std::string>& parts) {
    write_file(dir / "f.xyz", text);
    expect_input_error([&] { read_point_cloud_file(dir / "f.xyz"); }, parts);
  };
  rejected("0 0 0\n1 nan 2\n", { "f.xyz:2", "non-finite y" });
  rejected("0 0 0\n1 2 inf\n", { "f.xyz:2", "non-finite z" });
  rejected("0 0 0\n1 two 3\n", { "f.xyz:2", "column 2", "'two'" });
  rejected("0 0 0\n1 2\n", { "f.xyz:2", "2 columns" });
  rejected("1 2\n", { "f.xyz:1", "3 (x y z)" });
  rejected("0 0 0 255 128 0\n", { "f.xyz:1", "not a unit vector" }); // colours, not normals
  rejected("0 0 0 1.5\n", { "f.xyz:1", "confidence 1.5" });
  expect_input_error([&] { read_point_cloud_file(dir / "missing.xyz"); }, { "missing.xyz" });
  write_file(dir / "f.pcd", "");
  expect_input_error([&] { read_point_cloud_file(dir / "f.pcd"); }, { "f.pcd", ".ply or .xyz" });
}

TEST(PointCloudFile, ReadsAsciiPlySkippingColoursAndFaces) {
  ScratchDir dir;
  write_file(dir / "a.ply",
      "ply\nformat ascii 1.0\ncomment from a scanner\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty float nx\nproperty float "
      "ny\nproperty float nz\nproperty float confidence\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n0 1 2 255 0 0 1 0.5\n3 4 5 7 1 0 0 0.25\n3 0 1 1\n");
  const auto a = read_point_cloud_file(dir / "a.ply");
  ASSERT_EQ(a.points.rows(), 2);
  EXPECT_EQ(a.points.row(1), Eigen::RowVector3d(3, 4, 5));
  EXPECT_EQ(a.normals.row(0), Eigen::RowVector3d(0, 0, 1));
  EXPECT_EQ(a.confidence, Eigen::Vector2d(0.5, 0.25));

  write_file(dir / "bad.ply",
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty "
      "float z\nend_header\n0 0 0\n1 nan 0\n");
  expect_input_error(
      [&] { read_point_cloud_file(dir / "bad.ply"); }, { "bad.ply:9", "non-finite y" });
  write_file(dir / "short.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nend_header\n0 0 0\n1 1 0\n");
  expect_input_error(
      [&] { read_point_cloud_file(dir / "short.ply"); }, { "short.ply", "end of file" });
  write_file(dir / "noz.ply",
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 "
      "0\n");
  expect_input_error(
      [&] { read_point_cloud_file(dir / "noz.ply"); }, { "noz.ply", "lacks x, y or z" });
  write_file(dir / "empty.ply",
      "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty "
      "float z\nend_header\n");
  EXPECT_EQ(read_point_cloud_file(dir / "empty.ply").points.rows(), 0);
}

TEST(PointCloudFile, ReadsBinaryLittleEndianPly) {
  ScratchDir dir;
  std::string data = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\n"
                     "property double y\nproperty double z\nproperty uchar red\nproperty float "
                     "confidence\nend_header\n";
  put(data, 0.1), put(data, 0.2), put(data, 0.3), put(data, std::uint8_t(9)), put(data, 0.5f);
  put(data, -1.0), put(data, 2.0), put(data, 1.0 / 3), put(data, std::uint8_t(9)), put(data, 1.0f);
  write_file(dir / "b.ply", data);
  const auto b = read_point_cloud_file(dir / "b.ply");
  ASSERT_EQ(b.points.rows(), 2);
  EXPECT_EQ(b.points.row(0), Eigen::RowVector3d(0.1, 0.2, 0.3)); // doubles exactly
  EXPECT_EQ(b.points(1, 2), 1.0 / 3);
  EXPECT_EQ(b.confidence, Eigen::Vector2d(0.5, 1));
  write_file(dir / "t.ply", data.substr(0, data.size() - 3));
  expect_input_error([&] { read_point_cloud_file(dir / "t.ply"); }, { "t.ply", "truncated" });
  std::string nan = data;
  const double q = std::nan("");
  std::memcpy(&nan[nan.size() - 5 - 8], &q, 8);
  write_file(dir / "n.ply", nan);
  expect_input_error(
      [&] { read_point_cloud_file(dir / "n.ply"); }, { "n.ply", "vertex 1 of 2", "non-finite z" });
}

TEST(ImportPointClouds, OrdersFramesNaturallyAndKeepsEmptyFrames) {
  ScratchDir dir;
  for (int t : { 0, 1, 2, 10, 11 }) // frame_10 sorts after frame_2
    write_file(dir / ("frame_" + std::to_string(t) + ".xyz"),
        t == 1 ? "" : std::to_string(t) + " 0 0\n" + std::to_string(t) + " 1 0\n");
  write_file(dir / "notes.txt", "not a frame\n");
  std::filesystem::create_directory(dir / "sub.ply"); // a folder is not a frame
  const auto files = list_point_cloud_files(dir.path());
  ASSERT_EQ(files.size(), 5u);
  EXPECT_EQ(files[3].filename(), "frame_10.xyz");
  const capture::PointCloudSequence s = import_point_clouds(dir.path(), 0.02, 1.0);
  EXPECT_EQ(s.num_frames(), 5);
  EXPECT_EQ(s.offsets, (std::vector<Eigen::Index> { 0, 2, 2, 4, 6, 8 }));
  EXPECT_EQ(s.frame_points(3)(0, 0), 10);
  EXPECT_EQ(s.dt, 0.02);
  EXPECT_EQ(s.start_time, 1.0);
}

TEST(ImportPointClouds, ClearErrorsForFoldersAndDisagreeingFrames) {
  ScratchDir dir;
  expect_input_error([&] { list_point_cloud_files(dir.path()); }, { "no .ply or .xyz files" });
  expect_input_error([&] { list_point_cloud_files(dir / "nope"); }, { "nope", "no such folder" });
  write_file(dir / "f_1.xyz", "0 0 0\n");
  expect_input_error(
      [&] { list_point_cloud_files(dir / "f_1.xyz"); }, { "f_1.xyz", "not a folder" });
  write_file(dir / "f_2.xyz", "0 0 0 0 0 1\n");
  expect_input_error(
      [&] { import_point_clouds(dir.path(), 0.01); }, { "f_2.xyz", "has normals", "have none" });
  std::filesystem::remove(dir / "f_2.xyz");
  write_file(dir / "f_3.xyz", "0 0 0\n1 x 0\n");
  expect_input_error([&] { import_point_clouds(dir.path(), 0.01); }, { "f_3.xyz:2" });
  std::filesystem::remove(dir / "f_3.xyz");
  expect_input_error([&] { import_point_clouds(dir.path(), -1); }, { "dt", "positive" });
}
