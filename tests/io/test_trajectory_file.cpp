// Trajectory HDF5 files: exact round trips, the incremental writer, and one clear InputError for
// every kind of bad file (naming the file and the dataset), never a half-written output.
#include "io_test_util.hpp"

#include <elastolearn/io/hdf5_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;
namespace fs = std::filesystem;

namespace {

/// A small deterministic trajectory whose values use all 52 mantissa bits (so that an exact
/// comparison after the round trip means no value was rounded through float32 or text).
TrajectoryData make_trajectory(int frames, int n, bool velocities) {
  TrajectoryData d;
  d.rest_positions.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    d.rest_positions.row(i) << std::sin(1.0 + i), std::cos(0.3 * i) / 3.0, i * 0.1 + 1.0 / 7.0;
  }
  d.tets.resize(n - 3, 4);
  for (int k = 0; k < n - 3; ++k)
    d.tets.row(k) << k, k + 1, k + 2, k + 3;
  for (int t = 0; t < frames; ++t) {
    d.time.push_back(0.01 * (t + 1) / 3.0);
    Positions x = d.rest_positions;
    for (int i = 0; i < n; ++i)
      x(i, 1) += 1e-3 * std::sin(0.7 * t + i);
    d.positions.push_back(x);
    if (velocities)
      d.velocities.push_back(Positions::Constant(n, 3, std::exp(-t) / 11.0));
  }
  d.metadata
      = { { "scene", "bar.json" }, { "dt", "0.0033333333333333335" }, { "note", "ünïcode ok" } };
  return d;
}

void expect_same(const TrajectoryData& a, const TrajectoryData& b) {
  EXPECT_EQ(a.rest_positions, b.rest_positions);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.time, b.time);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t t = 0; t < a.positions.size(); ++t)
    EXPECT_EQ(a.positions[t], b.positions[t]);
  ASSERT_EQ(a.velocities.size(), b.velocities.size());
  for (std::size_t t = 0; t < a.velocities.size(); ++t)
    EXPECT_EQ(a.velocities[t], b.velocities[t]);
  EXPECT_EQ(a.metadata, b.metadata);
}

/// A trajectory file assembled dataset by dataset, so that tests can break exactly one thing.
struct RawFile {
  std::map<std::string, std::pair<std::vector<double>, h5::Shape>> f64;
  std::map<std::string, std::pair<std::vector<int>, h5::Shape>> i32;
  std::optional<std::string> format = "elastolearn-trajectory/1";

  /// Valid: T = 3 frames of n = 5 vertices, 2 tets.
  RawFile() {
    f64["/rest_positions"] = { std::vector<double>(15, 0.5), { 5, 3 } };
    f64["/positions"] = { std::vector<double>(45, 0.25), { 3, 5, 3 } };
    f64["/time"] = { { 0.0, 0.1, 0.2 }, { 3 } };
    i32["/tets"] = { { 0, 1, 2, 3, 1, 2, 3, 4 }, { 2, 4 } };
  }
  void write(const fs::path& path) const {
    h5::File file = h5::File::create(path);
    for (const auto& [name, data] : f64)
      file.write(name, data.first.data(), data.second);
    for (const auto& [name, data] : i32)
      file.write(name, data.first.data(), data.second);
    if (format)
      file.set_attribute("format", *format);
    file.close();
  }
};

/// Write `raw` and expect reading it to fail with a message containing `parts`.
void expect_rejected(const RawFile& raw, const fs::path& path, std::vector<std::string> parts) {
  raw.write(path);
  parts.insert(parts.begin(), path.string());
  expect_input_error([&] { read_trajectory_h5(path); }, parts);
}

} // namespace

TEST(TrajectoryFile, RoundTripIsExact) {
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(7, 9, true);
  write_trajectory_h5(dir / "t.h5", data);
  expect_same(data, read_trajectory_h5(dir / "t.h5"));
  EXPECT_EQ(dir.files(), std::vector<std::string> { "t.h5" }); // no temporary file left
}

TEST(TrajectoryFile, RoundTripOfASpringSystemWithoutTetsOrVelocities) {
  ScratchDir dir;
  TrajectoryData data = make_trajectory(4, 6, false);
  data.tets.resize(0, 4);
  data.edges.resize(5, 2);
  for (int i = 0; i < 5; ++i)
    data.edges.row(i) << i, i + 1;
  data.faces.resize(1, 3);
  data.faces.row(0) << 0, 2, 5;
  write_trajectory_h5(dir / "rope.h5", data);
  expect_same(data, read_trajectory_h5(dir / "rope.h5"));
}

TEST(TrajectoryFile, ZeroFramesIsAValidEmptyTrajectory) {
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(0, 5, false);
  write_trajectory_h5(dir / "empty.h5", data);
  expect_same(data, read_trajectory_h5(dir / "empty.h5"));
}

TEST(TrajectoryFile, FramesAreCompressedWhenDeflateIsAvailable) {
  ScratchDir dir;
  write_trajectory_h5(dir / "t.h5", make_trajectory(3, 5, true));
  const h5::File file = h5::File::open(dir / "t.h5");
  for (const char* name : { "/positions", "/velocities" }) {
    const hid_t ds = H5Dopen2(file.id(), name, H5P_DEFAULT);
    const hid_t dcpl = H5Dget_create_plist(ds);
    EXPECT_EQ(H5Pget_layout(dcpl), H5D_CHUNKED) << name;
    EXPECT_EQ(H5Pget_nfilters(dcpl), h5::deflate_available() ? 2 : 0) << name; // shuffle + deflate
    H5Pclose(dcpl);
    H5Dclose(ds);
  }
}

TEST(TrajectoryFile, MismatchedInputIsRejectedBeforeAnythingIsWritten) {
  ScratchDir dir;
  TrajectoryData data = make_trajectory(3, 5, false);
  data.time.pop_back();
  expect_input_error([&] { write_trajectory_h5(dir / "t.h5", data); },
      { "t.h5", "3 position frames but 2 times" });
  data = make_trajectory(3, 5, false);
  data.tets(1, 2) = 5;
  expect_input_error([&] { write_trajectory_h5(dir / "t.h5", data); },
      { "t.h5: /tets", "vertex index 5", "[0, 5)" });
  data = make_trajectory(3, 5, false);
  data.metadata["format"] = "mine";
  expect_input_error([&] { write_trajectory_h5(dir / "t.h5", data); }, { "metadata key 'format'" });
  EXPECT_TRUE(dir.files().empty());
}

TEST(TrajectoryFile, FailedWriteLeavesNoTemporaryAndKeepsTheOldFile) {
  ScratchDir dir;
  const TrajectoryData good = make_trajectory(2, 5, false);
  write_trajectory_h5(dir / "t.h5", good);
  TrajectoryData bad = make_trajectory(4, 5, false);
  bad.positions[2](3, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { write_trajectory_h5(dir / "t.h5", bad); },
      { "t.h5: /positions", "frame 2", "non-finite value nan at vertex 3" });
  EXPECT_EQ(dir.files(), std::vector<std::string> { "t.h5" });
  expect_same(good, read_trajectory_h5(dir / "t.h5"));
}

TEST(TrajectoryWriter, IncrementalWritingMatchesTheWholeTrajectory) {
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(300, 12, true); // > 1 chunk of frames
  {
    TrajectoryWriter writer(dir / "inc.h5", data.rest_positions, data.tets);
    for (std::size_t t = 0; t < data.positions.size(); ++t) {
      writer.append(data.time[t], data.positions[t], data.velocities[t]);
    }
    EXPECT_EQ(writer.frames(), 300);
    EXPECT_FALSE(fs::exists(dir / "inc.h5")); // published only by finish()
    writer.finish(data.metadata);
  }
  expect_same(data, read_trajectory_h5(dir / "inc.h5"));
}

TEST(TrajectoryWriter, StridedInputIsWrittenCorrectly) {
  ScratchDir dir;
  TrajectoryData data = make_trajectory(2, 6, false);
  Eigen::MatrixXd column_major = data.positions[1]; // not row-major: Ref makes a contiguous copy
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> wide(6, 6);
  wide.leftCols(3) = data.positions[0];
  wide.rightCols(3).setConstant(-1.0);
  {
    TrajectoryWriter writer(dir / "s.h5", data.rest_positions, data.tets);
    writer.append(data.time[0], wide.leftCols(3)); // row stride 6
    writer.append(data.time[1], column_major);
    writer.finish(data.metadata);
  }
  expect_same(data, read_trajectory_h5(dir / "s.h5"));
}

TEST(TrajectoryWriter, AbandonedWriterRemovesItsTemporaryFile) {
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(3, 5, false);
  try {
    TrajectoryWriter writer(dir / "t.h5", data.rest_positions, data.tets);
    writer.append(data.time[0], data.positions[0]);
    EXPECT_EQ(dir.files().size(), 1u); // the temporary file exists while writing
    throw std::runtime_error("simulation failed");
  } catch (const std::runtime_error&) { }
  EXPECT_TRUE(dir.files().empty());
}

TEST(TrajectoryWriter, KeepPartialPublishesTheFramesBeforeADivergence) {
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(6, 5, true);
  try {
    TrajectoryWriter writer(dir / "t.h5", data.rest_positions, data.tets);
    writer.keep_partial({ { "reason", "diverged at frame 4" } });
    for (std::size_t t = 0; t < data.positions.size(); ++t) {
      if (t == 4)
        throw std::runtime_error("diverged");
      writer.append(data.time[t], data.positions[t], data.velocities[t]);
    }
  } catch (const std::runtime_error&) { }
  EXPECT_EQ(dir.files(), std::vector<std::string> { "t.h5" });
  const TrajectoryData read = read_trajectory_h5(dir / "t.h5");
  ASSERT_EQ(read.positions.size(), 4u);
  ASSERT_EQ(read.velocities.size(), 4u);
  for (int t = 0; t < 4; ++t)
    EXPECT_EQ(read.positions[t], data.positions[t]);
  EXPECT_EQ(read.metadata.at("status"), "partial");
  EXPECT_EQ(read.metadata.at("reason"), "diverged at frame 4");
}

TEST(TrajectoryWriter, RejectedFrameLeavesTheFileConsistent) {
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(3, 5, false);
  {
    TrajectoryWriter writer(dir / "t.h5", data.rest_positions, data.tets);
    writer.append(data.time[0], data.positions[0]);
    Positions bad = data.positions[1];
    bad(0, 0) = std::numeric_limits<double>::infinity();
    expect_input_error(
        [&] { writer.append(data.time[1], bad); }, { "/positions", "frame 1", "inf" });
    expect_input_error(
        [&] { writer.append(data.time[0], data.positions[1]); }, { "/time", "does not increase" });
    expect_input_error([&] { writer.append(data.time[1], data.positions[1].topRows(4)); },
        { "has 4 vertices, expected 5" });
    expect_input_error([&] { writer.append(data.time[1], data.positions[1], data.positions[1]); },
        { "/velocities", "earlier frames have none" });
    writer.append(data.time[1], data.positions[1]);
    writer.finish();
  }
  const TrajectoryData read = read_trajectory_h5(dir / "t.h5");
  ASSERT_EQ(read.positions.size(), 2u);
  EXPECT_EQ(read.positions[1], data.positions[1]);
}

TEST(TrajectoryFile, OneFrameIsReadAloneAndMatchesTheWholeFile) {
  ScratchDir dir;
  for (bool velocities : { true, false }) {
    const TrajectoryData data = make_trajectory(7, 9, velocities);
    write_trajectory_h5(dir / "t.h5", data);
    EXPECT_EQ(read_trajectory_frame_count(dir / "t.h5"), 7);
    for (long k : { 0L, 4L, 6L }) {
      const TrajectoryFrame f = read_trajectory_frame(dir / "t.h5", k);
      EXPECT_EQ(f.index, k);
      EXPECT_EQ(f.frames, 7);
      EXPECT_EQ(f.time, data.time[k]);
      EXPECT_EQ(f.rest_positions, data.rest_positions);
      EXPECT_EQ(f.positions, data.positions[k]);
      if (velocities)
        EXPECT_EQ(f.velocities, data.velocities[k]);
      else
        EXPECT_EQ(f.velocities.rows(), 0); // absent, not zero
    }
    for (long k : { -1L, 7L })
      expect_input_error([&] { read_trajectory_frame(dir / "t.h5", k); },
          { "t.h5: /positions", "frame " + std::to_string(k) + " is out of range [0, 7)" });
  }
  RawFile raw; // the frame's shape is checked as when reading the whole file
  raw.f64["/velocities"] = { std::vector<double>(36, 0.0), { 3, 4, 3 } };
  raw.write(dir / "bad.h5");
  expect_input_error([&] { read_trajectory_frame(dir / "bad.h5", 1); },
      { "bad.h5: /velocities", "expected shape (T, n, 3) = (3, 5, 3), got (3, 4, 3)" });
}

// --- bad files: one clear error naming the file and the dataset -----------------------------

TEST(TrajectoryFileRejects, MissingDataset) {
  ScratchDir dir;
  for (const char* name : { "/positions", "/time", "/rest_positions" }) {
    RawFile raw;
    raw.f64.erase(name);
    expect_rejected(raw, dir / "missing.h5", { name, "missing dataset" });
  }
}

TEST(TrajectoryFileRejects, WrongShapes) {
  ScratchDir dir;
  RawFile raw;
  raw.f64["/positions"] = { std::vector<double>(36, 0.0), { 3, 4, 3 } };
  expect_rejected(
      raw, dir / "a.h5", { "/positions", "expected shape (T, n, 3) = (3, 5, 3), got (3, 4, 3)" });
  raw = RawFile();
  raw.f64["/rest_positions"] = { std::vector<double>(10, 0.0), { 5, 2 } };
  expect_rejected(raw, dir / "b.h5", { "/rest_positions", "expected shape (n, 3), got (5, 2)" });
  raw = RawFile();
  raw.i32["/tets"] = { { 0, 1, 2, 1, 2, 3 }, { 2, 3 } };
  expect_rejected(raw, dir / "c.h5", { "/tets", "expected shape (m, 4), got (2, 3)" });
}

TEST(TrajectoryFileRejects, FrameCountMismatchBetweenPositionsAndTime) {
  ScratchDir dir;
  RawFile raw;
  raw.f64["/time"] = { { 0.0, 0.1 }, { 2 } };
  expect_rejected(raw, dir / "t.h5", { "/positions", "has 3 frames but /time has 2" });
}

TEST(TrajectoryFileRejects, OutOfRangeOrNegativeIndex) {
  ScratchDir dir;
  RawFile raw;
  raw.i32["/tets"].first[6] = 5;
  expect_rejected(raw, dir / "a.h5", { "/tets", "vertex index 5 in row 1 is out of range [0, 5)" });
  raw = RawFile();
  raw.i32["/edges"] = { { 0, -1 }, { 1, 2 } };
  expect_rejected(raw, dir / "b.h5", { "/edges", "vertex index -1 in row 0" });
}

TEST(TrajectoryFileRejects, FloatIndices) {
  ScratchDir dir;
  RawFile raw;
  raw.i32.erase("/tets");
  raw.f64["/tets"] = { { 0, 1, 2, 3 }, { 1, 4 } };
  expect_rejected(raw, dir / "t.h5", { "/tets", "expected an integer dataset, got float" });
}

TEST(TrajectoryFileRejects, NonFiniteValues) {
  ScratchDir dir;
  RawFile raw;
  raw.f64["/positions"].first[2 * 15 + 4 * 3 + 2] = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(raw, dir / "a.h5",
      { "/positions", "frame 2: non-finite value nan at vertex 4 (component 2)" });
  raw = RawFile();
  raw.f64["/rest_positions"].first[0] = -std::numeric_limits<double>::infinity();
  expect_rejected(raw, dir / "b.h5", { "/rest_positions", "non-finite value -inf at vertex 0" });
  raw = RawFile();
  raw.f64["/time"].first[1] = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(raw, dir / "c.h5", { "/time", "frame 1: non-finite time" });
}

TEST(TrajectoryFileRejects, TimeThatDoesNotIncrease) {
  ScratchDir dir;
  RawFile raw;
  raw.f64["/time"] = { { 0.0, 0.2, 0.1 }, { 3 } };
  expect_rejected(
      raw, dir / "t.h5", { "/time", "frame 2: time 0.10000000000000001 does not increase" });
}

TEST(TrajectoryFileRejects, WrongOrMissingFormat) {
  ScratchDir dir;
  RawFile raw;
  raw.format = "elastolearn-scene/1";
  expect_rejected(
      raw, dir / "a.h5", { "format 'elastolearn-scene/1' is not an elastolearn trajectory" });
  raw.format = "elastolearn-trajectory/2";
  expect_rejected(raw, dir / "b.h5", { "newer than this elastolearn reads" });
  raw.format.reset();
  expect_rejected(raw, dir / "c.h5", { "root attribute 'format' is missing" });
}

TEST(TrajectoryFileRejects, TruncatedFile) {
  ScratchDir dir;
  write_trajectory_h5(dir / "t.h5", make_trajectory(50, 40, true));
  const auto size = fs::file_size(dir / "t.h5");
  for (const double fraction : { 0.9, 0.5, 0.1 }) {
    fs::copy_file(dir / "t.h5", dir / "cut.h5", fs::copy_options::overwrite_existing);
    fs::resize_file(dir / "cut.h5", std::uintmax_t(size * fraction));
    expect_input_error([&] { read_trajectory_h5(dir / "cut.h5"); }, { (dir / "cut.h5").string() });
  }
  fs::resize_file(dir / "cut.h5", 0);
  expect_input_error([&] { read_trajectory_h5(dir / "cut.h5"); }, { "cut.h5", "not an HDF5 file" });
}

TEST(TrajectoryFileRejects, CorruptChunk) {
  ScratchDir dir;
  write_trajectory_h5(dir / "t.h5", make_trajectory(50, 40, true));
  // Overwrite a stretch in the middle of the file (compressed frame data) with garbage.
  std::fstream f(dir / "t.h5", std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(std::streamoff(fs::file_size(dir / "t.h5") / 2));
  const std::string garbage(2000, '\x5a');
  f.write(garbage.data(), std::streamsize(garbage.size()));
  f.close();
  try {
    read_trajectory_h5(dir / "t.h5");
    // Without deflate the garbage may be valid doubles; with it, the chunk cannot inflate.
    EXPECT_FALSE(h5::deflate_available()) << "corrupt compressed data was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.h5"), std::string::npos) << e.what();
    if (h5::deflate_available()) {
      EXPECT_NE(std::string(e.what()).find("inflate() failed"), std::string::npos) << e.what();
    }
  }
}

TEST(TrajectoryFileRejects, NotAFileOrNotHdf5) {
  ScratchDir dir;
  expect_input_error([&] { read_trajectory_h5(dir / "none.h5"); }, { "none.h5", "no such file" });
  std::ofstream(dir / "text.h5") << "{\"format\": \"elastolearn-trajectory/1\"}";
  expect_input_error(
      [&] { read_trajectory_h5(dir / "text.h5"); }, { "text.h5", "not an HDF5 file" });
}

TEST(TrajectoryFileRejects, ErrorsAreNotPrintedByHdf5) {
  ScratchDir dir;
  write_trajectory_h5(dir / "t.h5", make_trajectory(5, 5, false));
  fs::resize_file(dir / "t.h5", fs::file_size(dir / "t.h5") / 2);
  testing::internal::CaptureStderr();
  EXPECT_THROW(read_trajectory_h5(dir / "t.h5"), InputError);
  RawFile raw;
  raw.f64.erase("/time");
  raw.write(dir / "m.h5");
  EXPECT_THROW(read_trajectory_h5(dir / "m.h5"), InputError);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// h5py reads our files and we read h5py's (int64 indices, its own string attributes). Skipped
// where /usr/bin/python3 has no h5py (Debian package python3-h5py).
TEST(TrajectoryFile, H5pyReadsAndWritesTheSameLayout) {
  if (std::system("/usr/bin/python3 -c 'import h5py' > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 with h5py not available";
  }
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(5, 8, true);
  write_trajectory_h5(dir / "ours.h5", data);
  std::ofstream(dir / "roundtrip_h5py.py") << R"(import sys, h5py, numpy as np
with h5py.File(sys.argv[1], "r") as f:
    assert f.attrs["format"] == "elastolearn-trajectory/1", f.attrs["format"]
    assert f.attrs["note"] == "ünïcode ok"
    assert f["positions"].shape == (5, 8, 3) and f["positions"].dtype == np.float64
    assert f["tets"].shape == (5, 4) and f["tets"].dtype.kind == "i"
    data = {k: f[k][()] for k in f}
    attrs = dict(f.attrs)
with h5py.File(sys.argv[2], "w") as g:
    for k, v in data.items():
        g[k] = v.astype(np.int64) if v.dtype.kind == "i" else v
    for k, v in attrs.items():
        g.attrs[k] = v
    g.attrs["written_by"] = "h5py"
)";
  const std::string command = "/usr/bin/python3 " + (dir / "roundtrip_h5py.py").string() + " "
      + (dir / "ours.h5").string() + " " + (dir / "theirs.h5").string();
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  TrajectoryData expected = data;
  expected.metadata["written_by"] = "h5py";
  expect_same(expected, read_trajectory_h5(dir / "theirs.h5"));
}

TEST(TrajectoryFileRejects, DatasetsThatDeclareMoreThanTheyStore) {
  // A few hundred bytes can declare 10⁹ frames: chunked /positions with no chunk written. The
  // reader must refuse it before allocating memory for the declared shape.
  ScratchDir dir;
  RawFile raw;
  raw.f64.erase("/positions");
  raw.write(dir / "huge.h5");
  {
    const hid_t file = H5Fopen((dir / "huge.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const h5::Shape shape { 1000000000, 5, 3 }, chunk { 1, 5, 3 };
    const hid_t space = H5Screate_simple(3, shape.data(), nullptr);
    const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(plist, 3, chunk.data());
    H5Dclose(
        H5Dcreate2(file, "/positions", H5T_IEEE_F64LE, space, H5P_DEFAULT, plist, H5P_DEFAULT));
    H5Pclose(plist);
    H5Sclose(space);
    H5Fclose(file);
  }
  EXPECT_LT(fs::file_size(dir / "huge.h5"), 100000u);
  // /time has 3 entries, so the frame count mismatch would be found too; the storage check
  // comes first because it runs when the dataset is opened.
  expect_input_error([&] { read_trajectory_h5(dir / "huge.h5"); },
      { "huge.h5: /positions", "declares shape (1000000000, 5, 3) but does not store all" });
}

TEST(TrajectoryFile, WrittenFilesCountAsFullyStored) {
  // Compressed chunks are smaller than the data they hold: the storage check counts chunks,
  // so every file the writer makes (many frames, several chunks, a partial last chunk) reads.
  ScratchDir dir;
  const TrajectoryData data = make_trajectory(300, 40, true);
  write_trajectory_h5(dir / "t.h5", data);
  expect_same(read_trajectory_h5(dir / "t.h5"), data);
}
