// Observation HDF5 files: exact round trip, files written the way docs/observations.md tells a
// user to write them, one clear InputError per kind of bad file (naming the file and the dataset
// or attribute), atomic output, and vertex-id lists.
#include "io_test_util.hpp"

#include <elastolearn/io/hdf5_file.hpp>
#include <elastolearn/io/observation_file.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <optional>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;
namespace fs = std::filesystem;

namespace {

/// T frames of k points with values that use all mantissa bits (exact comparison = no rounding).
observe::Observation make_observation(int T = 4, int k = 3) {
  observe::Observation obs;
  for (int j = 0; j < k; ++j)
    obs.vertex_ids.push_back(7 * j + 2);
  obs.dt = 1.0 / 30.0;
  obs.start_time = 0.1;
  for (int t = 0; t < T; ++t) {
    Positions x(k, 3);
    for (Eigen::Index i = 0; i < x.size(); ++i)
      x.data()[i] = std::sin(1.0 + i + 0.37 * t) / 3.0;
    obs.positions.push_back(x);
  }
  return obs;
}

/// An observation file assembled dataset by dataset (as h5py would), so that a test can break
/// exactly one thing. Valid: T = 3 frames of k = 2 points, dt = 0.01 as a string attribute.
struct RawFile {
  std::map<std::string, std::pair<std::vector<double>, h5::Shape>> f64;
  std::map<std::string, std::pair<std::vector<int>, h5::Shape>> i32;
  std::map<std::string, std::pair<std::vector<std::uint8_t>, h5::Shape>> u8;
  std::map<std::string, std::string> attributes { { "format", "elastolearn-observation/1" },
    { "dt", "0.01" } };

  RawFile() {
    i32["/observed/vertex_ids"] = { { 5, 1 }, { 2 } };
    f64["/observed/positions"] = { std::vector<double>(18, 0.25), { 3, 2, 3 } };
    f64["/time"] = { { 0.0, 0.01, 0.02 }, { 3 } };
  }
  void write(const fs::path& path) const {
    h5::File file = h5::File::create(path);
    for (const auto& [name, data] : f64)
      file.write(name, data.first.data(), data.second);
    for (const auto& [name, data] : i32)
      file.write(name, data.first.data(), data.second);
    for (const auto& [name, data] : u8)
      file.write(name, data.first.data(), data.second);
    for (const auto& [name, value] : attributes)
      file.set_attribute(name, value);
    file.close();
  }
};

/// Write `raw`, expect read_observation_h5 to fail with a message holding the file and `parts`.
void expect_rejected(const ScratchDir& dir, const RawFile& raw, std::vector<std::string> parts) {
  const fs::path path = dir / "bad.h5";
  fs::remove(path);
  raw.write(path);
  parts.push_back(path.string());
  expect_input_error([&] { read_observation_h5(path); }, parts);
}

} // namespace

TEST(ObservationFile, RoundTripIsExact) {
  ScratchDir dir;
  const observe::Observation obs = make_observation();
  write_observation_h5(dir / "obs.h5", obs);
  const observe::Observation back = read_observation_h5(dir / "obs.h5");
  EXPECT_EQ(back.vertex_ids, obs.vertex_ids);
  EXPECT_EQ(back.dt, obs.dt); // float64 attribute: bit-exact
  EXPECT_EQ(back.start_time, obs.start_time);
  ASSERT_EQ(back.num_frames(), obs.num_frames());
  for (int t = 0; t < obs.num_frames(); ++t)
    EXPECT_EQ(back.positions[t], obs.positions[t]);
  EXPECT_EQ(dir.files(), std::vector<std::string> { "obs.h5" }); // no temporary left behind

  // The documented layout, as h5py sees it.
  const h5::File file = h5::File::open(dir / "obs.h5");
  EXPECT_EQ(file.shape("/observed/positions"), (h5::Shape { 4, 3, 3 }));
  EXPECT_EQ(file.number_kind("/observed/vertex_ids"), h5::NumberKind::integer);
  EXPECT_EQ(file.attribute("format"), "elastolearn-observation/1");
  const std::vector<double> time = file.read_f64("/time");
  EXPECT_NEAR(time[3], 0.1 + 3.0 / 30.0, 1e-15);
}

TEST(ObservationFile, MetadataRoundTripAndRecognition) {
  ScratchDir dir;
  write_observation_h5(
      dir / "obs.h5", make_observation(), { { "noise_sigma", "0.0001" }, { "source", "traj.h5" } });
  EXPECT_EQ(read_observation_metadata(dir / "obs.h5"),
      (std::map<std::string, std::string> {
          { "noise_sigma", "0.0001" }, { "source", "traj.h5" } }));
  EXPECT_TRUE(is_observation_h5(dir / "obs.h5"));
  EXPECT_FALSE(is_observation_h5(dir / "missing.h5"));
  std::ofstream(dir / "text.h5") << "not hdf5";
  EXPECT_FALSE(is_observation_h5(dir / "text.h5"));
  // "format" and "dt" belong to the layout; nothing is written when they are misused.
  expect_input_error(
      [&] {
        write_observation_h5(dir / "bad.h5", make_observation(), { { "dt", "1" } });
      },
      { "bad.h5", "reserved" });
  EXPECT_FALSE(fs::exists(dir / "bad.h5"));
}

TEST(ObservationFile, ReadsAUserWrittenFile) {
  // dt as a numeric string, ids in any order: accepted, then checked against a scene.
  ScratchDir dir;
  RawFile().write(dir / "capture.h5");
  const observe::Observation obs = read_observation_h5(dir / "capture.h5");
  EXPECT_EQ(obs.vertex_ids, (std::vector<int> { 5, 1 }));
  EXPECT_EQ(obs.dt, 0.01);
  EXPECT_NO_THROW(obs.validate(6, 3, 0.01, (dir / "capture.h5").string()));
  // Checked against a scene with fewer vertices, other frames or another time step.
  const std::string name = (dir / "capture.h5").string();
  expect_input_error([&] { obs.validate(5, 3, 0.01, name); },
      { name, "/observed/vertex_ids", "vertex id 5", "[0, 5)" });
  expect_input_error([&] { obs.validate(6, 4, 0.01, name); }, { name, "3 frames", "expects 4" });
  expect_input_error([&] { obs.validate(6, 3, 0.005, name); }, { name, "dt", "0.01", "0.005" });
}

TEST(ObservationFile, RejectsEachKindOfBadFile) {
  ScratchDir dir;
  {
    RawFile r;
    r.attributes.erase("format");
    expect_rejected(dir, r, { "not an elastolearn observation", "format" });
  }
  {
    RawFile r;
    r.attributes["format"] = "elastolearn-trajectory/1";
    expect_rejected(dir, r, { "elastolearn-trajectory/1", "not an elastolearn observation" });
  }
  {
    RawFile r;
    r.attributes["format"] = "elastolearn-observation/3";
    expect_rejected(dir, r, { "newer" });
  }
  {
    RawFile r;
    r.attributes.erase("dt");
    expect_rejected(dir, r, { "attribute 'dt'", "missing" });
  }
  {
    RawFile r;
    r.attributes["dt"] = "fast";
    expect_rejected(dir, r, { "attribute 'dt'", "not a number", "fast" });
  }
  {
    RawFile r;
    r.attributes["dt"] = "-0.01";
    expect_rejected(dir, r, { "attribute 'dt'", "positive" });
  }
  {
    RawFile r;
    r.i32.erase("/observed/vertex_ids");
    expect_rejected(dir, r, { "/observed/vertex_ids", "missing dataset" });
  }
  {
    RawFile r;
    r.i32["/observed/vertex_ids"] = { { 5, 1 }, { 1, 2 } };
    expect_rejected(dir, r, { "/observed/vertex_ids", "(k,)", "(1, 2)" });
  }
  {
    RawFile r;
    r.i32.erase("/observed/vertex_ids");
    r.f64["/observed/vertex_ids"] = { { 5.0, 1.0 }, { 2 } };
    expect_rejected(dir, r, { "/observed/vertex_ids", "integer" });
  }
  {
    RawFile r;
    r.i32["/observed/vertex_ids"] = { { 5, 5 }, { 2 } };
    expect_rejected(dir, r, { "/observed/vertex_ids", "vertex id 5", "twice" });
  }
  {
    RawFile r;
    r.i32["/observed/vertex_ids"] = { { 5, -1 }, { 2 } };
    expect_rejected(dir, r, { "/observed/vertex_ids", "-1", "negative" });
  }
  {
    RawFile r;
    r.f64["/observed/positions"] = { std::vector<double>(27, 0.25), { 3, 3, 3 } };
    expect_rejected(dir, r, { "/observed/positions", "3 points per frame", "lists 2" });
  }
  {
    RawFile r;
    r.f64["/observed/positions"] = { std::vector<double>(12, 0.25), { 3, 2, 2 } };
    expect_rejected(dir, r, { "/observed/positions", "(T, k, 3)", "(3, 2, 2)" });
  }
  {
    RawFile r;
    r.f64["/observed/positions"].first[10] = std::nan("");
    expect_rejected(dir, r, { "/observed/positions", "frame 1", "non-finite", "vertex 1" });
  }
  {
    RawFile r;
    r.f64["/time"] = { { 0.0, 0.01 }, { 2 } };
    expect_rejected(dir, r, { "/time", "2 times", "3 frames" });
  }
  {
    RawFile r;
    r.f64["/time"] = { { 0.0, 0.01, 0.03 }, { 3 } };
    expect_rejected(dir, r, { "/time", "frames 1 and 2", "apart", "dt is 0.01" });
  }
  {
    RawFile r;
    r.f64["/time"] = { { 0.0, 0.01, NAN }, { 3 } };
    expect_rejected(dir, r, { "/time", "non-finite" });
  }
  expect_input_error(
      [&] { read_observation_h5(dir / "missing.h5"); }, { "missing.h5", "no such file" });
  {
    std::ofstream(dir / "text.h5") << "not hdf5\n";
    expect_input_error(
        [&] { read_observation_h5(dir / "text.h5"); }, { "text.h5", "not an HDF5 file" });
  }
}

TEST(ObservationFile, InvalidDataWritesNothing) {
  ScratchDir dir;
  observe::Observation obs = make_observation();
  obs.positions[2](0, 0) = INFINITY;
  expect_input_error([&] { write_observation_h5(dir / "obs.h5", obs); },
      { "obs.h5", "/observed/positions", "frame 2" });
  EXPECT_TRUE(dir.files().empty());
  // Overwriting keeps the old file when the new data are bad.
  write_observation_h5(dir / "obs.h5", make_observation());
  EXPECT_THROW(write_observation_h5(dir / "obs.h5", obs), InputError);
  EXPECT_EQ(read_observation_h5(dir / "obs.h5").num_frames(), 4);
  EXPECT_EQ(dir.files(), std::vector<std::string> { "obs.h5" });
}

TEST(ObservationFile, LostMarkersRoundTripWithNaNPositionsAndVersion2) {
  ScratchDir dir;
  observe::Observation obs = make_observation(5, 3);
  obs.valid = observe::ValidityMask::Ones(5, 3);
  obs.valid(1, 0) = obs.valid(2, 0) = obs.valid(4, 2) = 0;
  obs.positions[1].row(0).setConstant(std::nan(""));
  obs.positions[2].row(0) << 1e300, -1e300, INFINITY; // anything, where lost
  obs.positions[4](2, 1) = std::nan("");
  write_observation_h5(dir / "obs.h5", obs);
  const observe::Observation back = read_observation_h5(dir / "obs.h5");
  ASSERT_EQ(back.valid.rows(), 5);
  ASSERT_EQ(back.valid.cols(), 3);
  EXPECT_TRUE((back.valid == obs.valid).all());
  EXPECT_EQ(back.num_valid(), 12);
  for (int t = 0; t < 5; ++t)
    for (int j = 0; j < 3; ++j)
      if (obs.is_valid(t, j)) {
        EXPECT_EQ(back.positions[t].row(j), obs.positions[t].row(j));
      } else {
        EXPECT_FALSE(back.is_valid(t, j));
      }
  EXPECT_TRUE(std::isnan(back.positions[1](0, 0)));
  // A file with a mask says version 2 (an older reader refuses it rather than reading NaN or
  // garbage as data); one without stays version 1, and reads back without a mask.
  EXPECT_EQ(h5::File::open(dir / "obs.h5").attribute("format"), "elastolearn-observation/2");
  write_observation_h5(dir / "plain.h5", make_observation());
  EXPECT_EQ(h5::File::open(dir / "plain.h5").attribute("format"), "elastolearn-observation/1");
  EXPECT_EQ(read_observation_h5(dir / "plain.h5").valid.size(), 0);
}

TEST(ObservationFile, AcceptsAUserWrittenMaskAndRejectsEachKindOfBadOne) {
  ScratchDir dir;
  {
    // uint8 as the docs write it, NaN exactly where lost, a vertex never seen (ignored).
    RawFile r;
    r.attributes["format"] = "elastolearn-observation/2";
    r.u8["/observed/valid"] = { { 1, 0, 0, 0, 1, 0 }, { 3, 2 } };
    r.f64["/observed/positions"].first[3] = std::nan(""); // frame 0, point 1
    r.f64["/observed/positions"].first[6] = std::nan(""); // frame 1, point 0
    r.write(dir / "ok.h5");
    const observe::Observation o = read_observation_h5(dir / "ok.h5");
    EXPECT_EQ(o.num_valid(), 2);
    EXPECT_TRUE(o.is_valid(0, 0) && o.is_valid(2, 0) && !o.is_valid(1, 0));
  }
  {
    RawFile r; // any integer type: int32 0/1
    r.i32["/observed/valid"] = { { 1, 1, 0, 1, 1, 1 }, { 3, 2 } };
    r.write(dir / "ok32.h5");
    EXPECT_EQ(read_observation_h5(dir / "ok32.h5").num_valid(), 5);
  }
  {
    RawFile r;
    r.u8["/observed/valid"] = { { 1, 1, 1, 1 }, { 2, 2 } };
    expect_rejected(dir, r, { "/observed/valid", "expected shape (3, 2)", "(2, 2)" });
  }
  {
    RawFile r;
    r.u8["/observed/valid"] = { { 1, 1, 1, 1, 1, 1 }, { 6 } };
    expect_rejected(dir, r, { "/observed/valid", "expected shape (3, 2)", "(6,)" });
  }
  {
    RawFile r;
    r.i32["/observed/valid"] = { { 1, 1, 1, 2, 1, 1 }, { 3, 2 } };
    expect_rejected(dir, r, { "/observed/valid", "frame 1, entry 1", "value 2", "0 = lost" });
  }
  {
    RawFile r;
    r.i32["/observed/valid"] = { { 1, 1, 1, -1, 1, 1 }, { 3, 2 } };
    expect_rejected(dir, r, { "/observed/valid", "value -1" });
  }
  {
    RawFile r;
    r.f64["/observed/valid"] = { { 1, 1, 1, 0, 1, 1 }, { 3, 2 } };
    expect_rejected(dir, r, { "/observed/valid", "integers", "uint8" });
  }
  {
    RawFile r;
    r.u8["/observed/valid"] = { { 0, 0, 0, 0, 0, 0 }, { 3, 2 } };
    expect_rejected(dir, r, { "/observed/valid", "every entry is 0" });
  }
  {
    // NaN where the mask says seen: named as such.
    RawFile r;
    r.u8["/observed/valid"] = { { 1, 1, 0, 1, 1, 1 }, { 3, 2 } };
    r.f64["/observed/positions"].first[3] = std::nan(""); // frame 0, point 1: seen
    expect_rejected(dir, r,
        { "/observed/positions", "frame 0", "non-finite", "vertex 1",
            "/observed/valid marks as seen" });
  }
}

TEST(VertexIdList, ParsesCommentsCommasAndLines) {
  ScratchDir dir;
  std::ofstream(dir / "ids.txt") << "# picked markers\n3 17, 42\n\n  8\t9 # tail\r\n";
  EXPECT_EQ(read_vertex_id_list(dir / "ids.txt"), (std::vector<int> { 3, 17, 42, 8, 9 }));
  std::ofstream(dir / "bad.txt") << "1 2\n3 x4\n";
  expect_input_error([&] { read_vertex_id_list(dir / "bad.txt"); }, { "bad.txt:2", "'x4'" });
  std::ofstream(dir / "neg.txt") << "-3\n";
  expect_input_error([&] { read_vertex_id_list(dir / "neg.txt"); }, { "neg.txt:1", "'-3'" });
  std::ofstream(dir / "empty.txt") << "# nothing\n";
  expect_input_error(
      [&] { read_vertex_id_list(dir / "empty.txt"); }, { "empty.txt", "no vertex ids" });
  EXPECT_THROW(read_vertex_id_list(dir / "absent.txt"), InputError);
}
