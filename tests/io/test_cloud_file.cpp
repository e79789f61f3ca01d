// Point-cloud HDF5 files: round trip (with an empty frame, normals, confidence), the layout h5py
// sees, and one clear error for NaN, mismatched frame counts and broken offsets.
#include "io_test_util.hpp"

#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/hdf5_file.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

using namespace elastolearn;
using namespace elastolearn::io;
using elastolearn::io::test::expect_input_error;
using elastolearn::io::test::ScratchDir;

namespace {

capture::CloudFrame frame_of(int n, double shift, bool normals, bool confidence) {
  capture::CloudFrame f;
  f.points.resize(n, 3);
  for (int i = 0; i < n; ++i)
    f.points.row(i) << 0.1 * i + shift, -0.2 * i, 1.0 / 3.0 + shift;
  if (normals) {
    f.normals.resize(n, 3);
    for (int i = 0; i < n; ++i)
      f.normals.row(i) = Eigen::RowVector3d(1, i, 2).normalized();
  }
  if (confidence) {
    f.confidence.resize(n);
    for (int i = 0; i < n; ++i)
      f.confidence[i] = 1.0 / (i + 1);
  }
  return f;
}

capture::PointCloudSequence sequence(bool normals, bool confidence) {
  return capture::PointCloudSequence::from_frames(
      { frame_of(3, 0, normals, confidence), frame_of(0, 0, normals, confidence), // empty frame
          frame_of(5, 0.7, normals, confidence) },
      0.01, 0.5, "test");
}

/// Write raw datasets (no validation) to make broken files.
struct Raw {
  std::vector<double> points { 0, 0, 0, 1, 1, 1, 2, 2, 2 };
  std::vector<std::int64_t> offsets { 0, 2, 3 };
  std::vector<double> time { 0, 0.01 };
  std::string dt = "0.01";
  void write(const std::filesystem::path& path) const {
    h5::File f = h5::File::create(path);
    f.write("/clouds/points", points.data(), { points.size() / 3, 3 });
    f.write("/clouds/offsets", offsets.data(), { offsets.size() });
    f.write("/time", time.data(), { time.size() });
    f.set_attribute("format", "elastolearn-clouds/1");
    f.set_attribute("dt", dt);
    f.close();
  }
};

} // namespace

TEST(CloudFile, RoundTripsFramesEmptyFramesNormalsAndConfidence) {
  ScratchDir dir;
  for (bool normals : { false, true })
    for (bool confidence : { false, true }) {
      const capture::PointCloudSequence s = sequence(normals, confidence);
      const auto path = dir / "c.h5";
      write_clouds_h5(path, s, { { "source", "test" } });
      const capture::PointCloudSequence r = read_clouds_h5(path);
      EXPECT_EQ(r.offsets, (std::vector<Eigen::Index> { 0, 3, 3, 8 }));
      EXPECT_EQ(r.points, s.points); // bit for bit
      EXPECT_EQ(r.has_normals(), normals);
      EXPECT_EQ(r.has_confidence(), confidence);
      if (normals) {
        EXPECT_EQ(r.normals, s.normals);
      }
      if (confidence) {
        EXPECT_EQ(r.confidence, s.confidence);
      }
      EXPECT_EQ(r.dt, 0.01);
      EXPECT_EQ(r.start_time, 0.5);
      EXPECT_EQ(r.frame_size(1), 0);
      EXPECT_EQ(read_clouds_metadata(path).at("source"), "test");
      EXPECT_TRUE(is_clouds_h5(path));
      EXPECT_EQ(dir.files(), std::vector<std::string> { "c.h5" }); // no temporary left
    }
}

TEST(CloudFile, LayoutIsWhatTheDocumentationTellsH5pyUsers) {
  ScratchDir dir;
  write_clouds_h5(dir / "c.h5", sequence(true, false));
  const h5::File f = h5::File::open(dir / "c.h5");
  EXPECT_EQ(f.shape("/clouds/points"), (h5::Shape { 8, 3 }));
  EXPECT_EQ(f.shape("/clouds/offsets"), (h5::Shape { 4 }));
  EXPECT_EQ(f.number_kind("/clouds/offsets"), h5::NumberKind::integer);
  EXPECT_EQ(f.shape("/clouds/normals"), (h5::Shape { 8, 3 }));
  EXPECT_FALSE(f.exists("/clouds/confidence"));
  EXPECT_EQ(f.read_f64("/time"), (std::vector<double> { 0.5, 0.51, 0.52 }));
  EXPECT_EQ(f.attribute("format"), "elastolearn-clouds/1");
  EXPECT_EQ(f.attribute("dt"), "0.01");
}

TEST(CloudFile, AllFramesEmptyIsAValidFile) {
  ScratchDir dir;
  const auto s = capture::PointCloudSequence::from_frames({ {}, {} }, 0.1, 0, "test");
  write_clouds_h5(dir / "c.h5", s);
  const auto r = read_clouds_h5(dir / "c.h5");
  EXPECT_EQ(r.num_frames(), 2);
  EXPECT_EQ(r.num_points(), 0);
}

TEST(CloudFile, WriterRefusesABadFrameAndLeavesNoFile) {
  ScratchDir dir;
  {
    CloudWriter writer(dir / "c.h5", 0.01);
    writer.append(frame_of(2, 0, false, false));
    capture::CloudFrame nan = frame_of(2, 0, false, false);
    nan.points(1, 2) = std::nan("");
    expect_input_error([&] { writer.append(nan); },
        { "c.h5", "/clouds/points", "frame 1, point 1", "non-finite" });
    expect_input_error([&] { writer.append(frame_of(2, 0, true, false)); },
        { "c.h5: frame 1", "has normals", "have none" });
    capture::CloudFrame colour = frame_of(2, 0, false, false);
    colour.normals = Positions::Constant(2, 3, 255);
    expect_input_error([&] { writer.append(colour); }, { "not a unit vector" });
  }
  EXPECT_TRUE(dir.files().empty());
  expect_input_error([&] { CloudWriter(dir / "d.h5", 0); }, { "d.h5", "dt" });
}

TEST(CloudFile, ReaderNamesTheFileAndDatasetOfEachProblem) {
  ScratchDir dir;
  const auto path = dir / "bad.h5";
  const auto rejected = [&](const Raw& raw, const std::vector<std::string>& parts) {
    raw.write(path);
    expect_input_error([&] { read_clouds_h5(path); }, parts);
    std::filesystem::remove(path);
  };
  Raw ok;
  ok.write(path);
  EXPECT_EQ(read_clouds_h5(path).num_frames(), 2);

  Raw nan;
  nan.points[4] = std::nan("");
  rejected(nan, { "bad.h5: /clouds/points", "frame 0, point 1", "non-finite" });
  Raw inf;
  inf.points[8] = INFINITY;
  rejected(inf, { "/clouds/points", "frame 1, point 0" });
  Raw frames; // 3 times for 2 frames
  frames.time = { 0, 0.01, 0.02 };
  rejected(frames, { "bad.h5: /time", "3 frames", "/clouds/offsets" });
  Raw decreasing;
  decreasing.offsets = { 0, 3, 2 };
  rejected(decreasing, { "/clouds/offsets", "must not decrease" });
  Raw short_end;
  short_end.offsets = { 0, 1, 2 };
  rejected(short_end, { "/clouds/offsets", "ends at 2", "3 points" });
  Raw beyond;
  beyond.offsets = { 0, 1, 7 };
  rejected(beyond, { "/clouds/offsets", "outside [0, N = 3]" });
  Raw late_start;
  late_start.offsets = { 1, 2, 3 };
  rejected(late_start, { "/clouds/offsets", "start at 0" });
  Raw no_frames;
  no_frames.offsets = { 0 };
  no_frames.points.clear();
  no_frames.time.clear();
  rejected(no_frames, { "/clouds/offsets", "at least one frame" });
  Raw dt;
  dt.dt = "nan";
  rejected(dt, { "bad.h5", "dt" });
  Raw uneven;
  uneven.time = { 0, 0.02 };
  rejected(uneven, { "/time", "apart" });

  // Float offsets, normals of the wrong size, another kind of file.
  const auto write = [&](const std::string& name, bool float_offsets, int normal_rows) {
    h5::File f = h5::File::create(dir / name);
    const std::vector<double> points(9, 0.0), time { 0, 0.01 }, float_offsets_data { 0, 2, 3 };
    const std::vector<std::int64_t> offsets { 0, 2, 3 };
    std::vector<double> normals;
    for (int i = 0; i < normal_rows; ++i)
      normals.insert(normals.end(), { 0.0, 0.0, 1.0 });
    f.write("/clouds/points", points.data(), { 3, 3 });
    if (float_offsets)
      f.write("/clouds/offsets", float_offsets_data.data(), { 3 });
    else
      f.write("/clouds/offsets", offsets.data(), { 3 });
    if (normal_rows > 0)
      f.write("/clouds/normals", normals.data(), { hsize_t(normal_rows), 3 });
    f.write("/time", time.data(), { 2 });
    f.set_attribute("format", "elastolearn-clouds/1");
    f.set_attribute("dt", "0.01");
    f.close();
  };
  write("f.h5", true, 0);
  expect_input_error([&] { read_clouds_h5(dir / "f.h5"); }, { "f.h5: /clouds/offsets", "integer" });
  write("n.h5", false, 2);
  expect_input_error(
      [&] { read_clouds_h5(dir / "n.h5"); }, { "n.h5: /clouds/normals", "2 rows", "3" });
  std::filesystem::remove(path);
  {
    h5::File f = h5::File::create(path);
    f.set_attribute("format", "elastolearn-trajectory/1");
    f.close();
  }
  expect_input_error([&] { read_clouds_h5(path); }, { "bad.h5", "not an elastolearn point-cloud" });
  EXPECT_FALSE(is_clouds_h5(path));
}
