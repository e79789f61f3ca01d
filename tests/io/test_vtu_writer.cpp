// VTU/PVD output: parse the XML back minimally and check that every DataArray decodes to exactly
// the values written (UInt64 byte-count header + raw bytes, one base64 stream), and that the PVD
// lists every frame with its time.
#include "io_test_util.hpp"

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/io/vtu_writer.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <regex>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;
namespace fs = std::filesystem;

namespace {

std::vector<unsigned char> decode_base64(const std::string& text) {
  std::vector<unsigned char> out;
  std::uint32_t buffer = 0;
  int bits = 0;
  for (char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z')
      v = c - 'A';
    else if (c >= 'a' && c <= 'z')
      v = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      v = c - '0' + 52;
    else if (c == '+')
      v = 62;
    else if (c == '/')
      v = 63;
    else if (c == '=')
      break;
    else
      continue; // whitespace
    buffer = (buffer << 6) | std::uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((buffer >> bits) & 0xff));
    }
  }
  return out;
}

/// A parsed DataArray: its attributes and decoded payload (after the UInt64 header).
struct Array {
  std::string type;
  int components = 1;
  std::vector<unsigned char> bytes;
  template <typename T> std::vector<T> values() const {
    std::vector<T> v(bytes.size() / sizeof(T));
    std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
    return v;
  }
};

struct Vtu {
  long points = -1, cells = -1;
  std::map<std::string, Array> arrays;
};

Vtu parse_vtu(const fs::path& path) {
  const std::string xml = read_text_file(path);
  Vtu vtu;
  EXPECT_NE(xml.find("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\""), std::string::npos);
  EXPECT_NE(xml.find("header_type=\"UInt64\""), std::string::npos);
  std::smatch m;
  if (std::regex_search(
          xml, m, std::regex(R"re(NumberOfPoints="(\d+)" NumberOfCells="(\d+)")re"))) {
    vtu.points = std::stol(m[1]);
    vtu.cells = std::stol(m[2]);
  }
  const std::regex array_re(
      R"re(<DataArray type="(\w+)" Name="(\w+)"(?: NumberOfComponents="(\d)")? format="binary">([^<]*)</DataArray>)re");
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), array_re);
       it != std::sregex_iterator(); ++it) {
    Array a;
    a.type = (*it)[1];
    a.components = (*it)[3].matched ? std::stoi((*it)[3]) : 1;
    std::vector<unsigned char> raw = decode_base64((*it)[4]);
    EXPECT_GE(raw.size(), 8u);
    std::uint64_t header = 0;
    std::memcpy(&header, raw.data(), 8);
    EXPECT_EQ(header, raw.size() - 8) << "byte-count header of " << (*it)[2];
    a.bytes.assign(raw.begin() + 8, raw.end());
    vtu.arrays[(*it)[2]] = a;
  }
  return vtu;
}

std::vector<double> flat(const Positions& x) {
  return { x.data(), x.data() + x.size() };
}

TrajectoryData small_trajectory(bool velocities) {
  TrajectoryData d;
  d.rest_positions.resize(5, 3);
  d.rest_positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
  d.tets.resize(2, 4);
  d.tets << 0, 1, 2, 3, 1, 2, 3, 4;
  for (int t = 0; t < 3; ++t) {
    d.time.push_back(0.1 * t + 1.0 / 3.0);
    d.positions.push_back(d.rest_positions * (1.0 + 0.01 * t) + Positions::Constant(5, 3, 0.1 * t));
    if (velocities)
      d.velocities.push_back(Positions::Constant(5, 3, -1.0 / (t + 3)));
  }
  return d;
}

} // namespace

TEST(Base64, MatchesRfc4648Vectors) {
  const std::vector<std::pair<std::string, std::string>> cases
      = { { "", "" }, { "f", "Zg==" }, { "fo", "Zm8=" }, { "foo", "Zm9v" }, { "foob", "Zm9vYg==" },
          { "fooba", "Zm9vYmE=" }, { "foobar", "Zm9vYmFy" } };
  for (const auto& [in, expected] : cases) {
    std::string out = "x";
    append_base64(out, in.data(), in.size());
    EXPECT_EQ(out, "x" + expected);
    EXPECT_EQ(decode_base64(expected), std::vector<unsigned char>(in.begin(), in.end()));
  }
}

TEST(VtuSeries, EveryFrameDecodesToTheWrittenValues) {
  ScratchDir dir;
  const TrajectoryData data = small_trajectory(true);
  const fs::path pvd = write_vtu_series(dir.path() / "out", "bar", data);
  EXPECT_EQ(pvd, dir.path() / "out" / "bar.pvd");
  for (int t = 0; t < 3; ++t) {
    const Vtu vtu = parse_vtu(dir.path() / "out" / ("bar_000" + std::to_string(t) + ".vtu"));
    EXPECT_EQ(vtu.points, 5);
    EXPECT_EQ(vtu.cells, 2);
    ASSERT_EQ(
        vtu.arrays.size(), 6u); // displacement, velocity, Points, connectivity, offsets, types
    EXPECT_EQ(vtu.arrays.at("Points").values<double>(), flat(data.positions[t]));
    EXPECT_EQ(vtu.arrays.at("Points").components, 3);
    const Positions u = data.positions[t] - data.rest_positions;
    EXPECT_EQ(vtu.arrays.at("displacement").values<double>(), flat(u));
    EXPECT_EQ(vtu.arrays.at("velocity").values<double>(), flat(data.velocities[t]));
    EXPECT_EQ(vtu.arrays.at("connectivity").type, "Int32");
    EXPECT_EQ(vtu.arrays.at("connectivity").values<std::int32_t>(),
        (std::vector<std::int32_t> { 0, 1, 2, 3, 1, 2, 3, 4 }));
    EXPECT_EQ(
        vtu.arrays.at("offsets").values<std::int64_t>(), (std::vector<std::int64_t> { 4, 8 }));
    EXPECT_EQ(
        vtu.arrays.at("types").values<std::uint8_t>(), (std::vector<std::uint8_t> { 10, 10 }));
  }
  // The PVD lists every frame once, in order, with its exact time.
  const std::string xml = read_text_file(pvd);
  const std::regex dataset_re(
      R"re(<DataSet timestep="([^"]+)" group="" part="0" file="([^"]+)"/>)re");
  std::vector<std::pair<double, std::string>> entries;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), dataset_re);
       it != std::sregex_iterator(); ++it) {
    entries.emplace_back(std::stod((*it)[1]), (*it)[2]);
  }
  ASSERT_EQ(entries.size(), 3u);
  for (int t = 0; t < 3; ++t) {
    EXPECT_EQ(entries[t].first, data.time[t]); // shortest round-trip text: exact
    EXPECT_EQ(entries[t].second, "bar_000" + std::to_string(t) + ".vtu");
    EXPECT_TRUE(fs::exists(dir.path() / "out" / entries[t].second));
  }
  EXPECT_EQ(dir.files().size(), 1u); // only "out"
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "out"), {}), 4); // 3 VTU + PVD, no temp
}

TEST(VtuSeries, CellTypeFollowsTheElementsPresent) {
  ScratchDir dir;
  TrajectoryData data = small_trajectory(false);
  data.tets.resize(0, 4);
  data.faces.resize(1, 3);
  data.faces << 0, 1, 2;
  data.edges.resize(2, 2);
  data.edges << 0, 4, 1, 4;
  write_vtu_series(dir.path(), "faces", data);
  Vtu vtu = parse_vtu(dir / "faces_0000.vtu");
  EXPECT_EQ(vtu.arrays.at("types").values<std::uint8_t>(), std::vector<std::uint8_t> { 5 });
  EXPECT_EQ(vtu.arrays.count("velocity"), 0u);

  data.faces.resize(0, 3);
  write_vtu_series(dir.path(), "edges", data);
  vtu = parse_vtu(dir / "edges_0000.vtu");
  EXPECT_EQ(vtu.arrays.at("types").values<std::uint8_t>(), (std::vector<std::uint8_t> { 3, 3 }));
  EXPECT_EQ(vtu.arrays.at("connectivity").values<std::int32_t>(),
      (std::vector<std::int32_t> { 0, 4, 1, 4 }));

  data.edges.resize(0, 2);
  write_vtu_series(dir.path(), "cloud", data);
  vtu = parse_vtu(dir / "cloud_0000.vtu");
  EXPECT_EQ(vtu.cells, 5);
  EXPECT_EQ(vtu.arrays.at("types").values<std::uint8_t>(), std::vector<std::uint8_t>(5, 1));
}

TEST(Vtu, SingleFrameWithAnEmptyCellBlock) {
  ScratchDir dir;
  const Positions x = Positions::Random(4, 3);
  write_vtu(dir / "one.vtu", x, Tets());
  const Vtu vtu = parse_vtu(dir / "one.vtu");
  EXPECT_EQ(vtu.points, 4);
  EXPECT_EQ(vtu.cells, 0);
  EXPECT_EQ(vtu.arrays.at("Points").values<double>(), flat(x));
  EXPECT_TRUE(vtu.arrays.at("connectivity").bytes.empty());
}

TEST(Vtu, InconsistentInputIsAnInputErrorNamingTheFile) {
  ScratchDir dir;
  const TrajectoryData data = small_trajectory(false);
  expect_input_error([&] { write_vtu(dir / "a.vtu", data.rest_positions.topRows(4), data.tets); },
      { "a.vtu", "references vertex 4 but there are only 4 points" });
  const Positions short_field = Positions::Zero(3, 3);
  expect_input_error(
      [&] {
        write_vtu(dir / "b.vtu", data.rest_positions, data.tets, { { "u", short_field } });
      },
      { "b.vtu", "point data 'u' has 3 rows, expected 5" });
  TrajectoryData bad = data;
  bad.time.pop_back();
  expect_input_error(
      [&] { write_vtu_series(dir.path(), "c", bad); }, { "3 position frames but 2 times" });
  bad = data;
  bad.positions[1] = data.rest_positions.topRows(4);
  expect_input_error(
      [&] { write_vtu_series(dir.path(), "d", bad); }, { "frame 1 has 4 vertices, expected 5" });
  EXPECT_FALSE(fs::exists(dir / "d.pvd"));
}
