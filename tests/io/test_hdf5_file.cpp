// The RAII layer over HDF5: shapes, partial reads, groups, attributes, and silent failures.
#include "io_test_util.hpp"

#include <elastolearn/io/hdf5_file.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;

TEST(Hdf5File, WritesReadsAndSlicesWithIntermediateGroups) {
  ScratchDir dir;
  const std::vector<double> values { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11 };
  const std::vector<int> ids { 4, 8, 15, 16, 23 };
  {
    h5::File file = h5::File::create(dir / "a.h5");
    file.write("/observed/positions", values.data(), { 2, 2, 3 });
    file.write("/observed/vertex_ids", ids.data(), { 5 });
    file.close();
  }
  const h5::File file = h5::File::open(dir / "a.h5");
  EXPECT_TRUE(file.exists("/observed"));
  EXPECT_TRUE(file.exists("/observed/vertex_ids"));
  EXPECT_FALSE(file.exists("/missing/vertex_ids"));
  EXPECT_EQ(file.shape("/observed/positions"), (h5::Shape { 2, 2, 3 }));
  EXPECT_EQ(file.read_f64("/observed/positions"), values);
  EXPECT_EQ(file.read_i32("/observed/vertex_ids"), ids);
  EXPECT_EQ(file.number_kind("/observed/vertex_ids"), h5::NumberKind::integer);
  std::vector<double> second(6);
  file.dataset("/observed/positions").read(second.data(), 1, 1);
  EXPECT_EQ(second, std::vector<double>(values.begin() + 6, values.end()));
  // Integers widen to double; doubles never narrow to int silently.
  EXPECT_EQ(file.read_f64("/observed/vertex_ids"), (std::vector<double> { 4, 8, 15, 16, 23 }));
  expect_input_error([&] { file.read_i32("/observed/positions"); },
      { "a.h5: /observed/positions", "expected an integer dataset, got float" });
  expect_input_error([&] { file.dataset("/observed/positions").read(second.data(), 1, 2); },
      { "cannot read rows [1, 3) of shape (2, 2, 3)" });
  expect_input_error([&] { file.shape("/nothing"); }, { "a.h5: /nothing", "missing dataset" });
  expect_input_error(
      [&] { file.shape("/observed"); }, { "a.h5: /observed", "not a readable dataset" });
}

TEST(Hdf5File, StringAttributesRoundTripAndReplace) {
  ScratchDir dir;
  {
    h5::File file = h5::File::create(dir / "a.h5");
    const double x = 1.5;
    file.write("/x", &x, {});
    file.set_attribute("format", "first");
    file.set_attribute("format", "second");
    file.set_attribute("unit", "m", "/x");
    file.set_attribute("empty", "");
    file.close();
  }
  const h5::File file = h5::File::open(dir / "a.h5");
  EXPECT_EQ(file.attribute("format"), "second");
  EXPECT_EQ(file.attribute("unit", "/x"), "m");
  EXPECT_EQ(file.attribute("absent"), std::nullopt);
  EXPECT_EQ(file.attributes(),
      (std::map<std::string, std::string> { { "empty", "" }, { "format", "second" } }));
  EXPECT_EQ(file.shape("/x"), h5::Shape {});
}

TEST(Hdf5File, AppendableDatasetGrowsFrameByFrameAcrossChunks) {
  ScratchDir dir;
  constexpr int frames = 5000; // > the 4096-frame chunk of a scalar series
  {
    h5::File file = h5::File::create(dir / "a.h5");
    h5::AppendableDataset series(file, "/series", {});
    h5::AppendableDataset pairs(file, "/pairs", { 2 });
    for (int t = 0; t < frames; ++t) {
      const double v = t * 0.5, p[2] = { double(t), -double(t) };
      series.append(&v);
      pairs.append(p);
    }
    EXPECT_EQ(series.frames(), hsize_t(frames));
    series.close();
    pairs.close();
    file.close();
  }
  const h5::File file = h5::File::open(dir / "a.h5");
  EXPECT_EQ(file.shape("/pairs"), (h5::Shape { frames, 2 }));
  const std::vector<double> series = file.read_f64("/series"), pairs = file.read_f64("/pairs");
  for (int t = 0; t < frames; ++t) {
    ASSERT_EQ(series[t], t * 0.5);
    ASSERT_EQ(pairs[2 * t + 1], -double(t));
  }
}

TEST(Hdf5File, CreateInAMissingDirectoryFailsWithTheName) {
  ScratchDir dir;
  expect_input_error([&] { h5::File::create(dir / "no" / "such" / "dir.h5"); },
      { "dir.h5", "cannot create HDF5 file" });
}

TEST(Hdf5File, ShapeStringLooksLikeNumpy) {
  EXPECT_EQ(h5::shape_string({}), "()");
  EXPECT_EQ(h5::shape_string({ 4 }), "(4,)");
  EXPECT_EQ(h5::shape_string({ 10, 12, 3 }), "(10, 12, 3)");
}
