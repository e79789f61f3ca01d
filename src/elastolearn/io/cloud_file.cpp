#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/hdf5_file.hpp>

#include <charconv>
#include <cmath>
#include <optional>

namespace elastolearn::io {

namespace {

constexpr const char* k_clouds_kind = "elastolearn-clouds";
constexpr int k_clouds_version = 1;
const std::string k_points = "/clouds/points";
const std::string k_offsets = "/clouds/offsets";
const std::string k_normals = "/clouds/normals";
const std::string k_confidence = "/clouds/confidence";
const std::string k_time = "/time";

/// Append the rows of an N×3 row-major array (or N values) to a dataset.
template <typename Rows> void append_rows(h5::AppendableDataset& dataset, const Rows& rows) {
  const Eigen::Index width = rows.cols();
  for (Eigen::Index i = 0; i < rows.rows(); ++i)
    dataset.append(rows.data() + i * width);
}

double read_dt(const h5::File& file) {
  return file.positive_attribute("dt", "the time between frames, in seconds");
}

h5::Shape shape_of(const h5::File& file, const std::string& dataset, std::size_t rank,
    bool three_columns, const std::string& pattern) {
  const h5::Shape shape = file.shape(dataset);
  if (shape.size() != rank || (three_columns && shape[1] != 3))
    file.fail(dataset, "expected shape " + pattern + ", got " + h5::shape_string(shape));
  return shape;
}

} // namespace

struct CloudWriter::Impl {
  Impl(const std::filesystem::path& path, double dt_, double start)
      : atomic(path)
      , name(path.string())
      , file(h5::File::create(atomic.temp_path(), name))
      , dt(dt_)
      , start_time(start)
      , points(file, k_points, { 3 }, false) { }

  AtomicFile atomic; ///< destroyed last: removes the temporary file unless committed
  std::string name;
  h5::File file;
  double dt;
  double start_time;
  h5::AppendableDataset points;
  std::optional<h5::AppendableDataset> normals;
  std::optional<h5::AppendableDataset> confidence;
  std::vector<std::int64_t> offsets { 0 };
  capture::FrameLayout layout;
  bool failed = false; ///< a frame was written only in part
  bool finished = false;
};

CloudWriter::CloudWriter(const std::filesystem::path& path, double dt, double start_time) {
  if (!std::isfinite(dt) || dt <= 0)
    throw InputError(path.string() + ": dt", "must be positive and finite, got " + to_text(dt));
  if (!std::isfinite(start_time))
    throw InputError(path.string() + ": /time", "non-finite start time");
  m_impl = std::make_unique<Impl>(path, dt, start_time);
}

CloudWriter::~CloudWriter() = default;

long CloudWriter::frames() const {
  return static_cast<long>(m_impl->offsets.size()) - 1;
}

long long CloudWriter::points() const {
  return m_impl->offsets.back();
}

void CloudWriter::append(const capture::CloudFrame& frame) {
  Impl& s = *m_impl;
  if (s.finished)
    throw InputError(s.name, "cannot append to a finished file");
  const int t = static_cast<int>(frames());
  frame.validate(s.name, t);
  const Eigen::Index n = frame.points.rows();
  s.layout.check(frame, s.name + ": frame " + std::to_string(t));
  if (s.failed)
    throw InputError(s.name, "an earlier write failed; the file cannot be continued");
  if (n > 0) {
    // A write that fails half-way leaves the datasets out of step: the file is then never
    // published (finish refuses, the destructor removes it).
    s.failed = true;
    if (s.layout.normals() && !s.normals)
      s.normals.emplace(s.file, k_normals, h5::Shape { 3 }, false);
    if (s.layout.confidence() && !s.confidence)
      s.confidence.emplace(s.file, k_confidence, h5::Shape {}, false);
    append_rows(s.points, frame.points);
    if (s.normals)
      append_rows(*s.normals, frame.normals);
    if (s.confidence)
      for (Eigen::Index j = 0; j < n; ++j)
        s.confidence->append(&frame.confidence[j]);
    s.failed = false;
  }
  s.offsets.push_back(s.offsets.back() + n);
}

void CloudWriter::finish(const std::map<std::string, std::string>& metadata) {
  Impl& s = *m_impl;
  if (s.finished)
    throw InputError(s.name, "already finished");
  if (s.failed)
    throw InputError(s.name, "an earlier write failed; nothing was published");
  if (frames() < 1)
    throw InputError(s.name + ": " + k_offsets, "no frames to write");
  for (const auto& [key, value] : metadata)
    if (key.empty() || key == "format" || key == "dt")
      throw InputError(s.name, "invalid metadata key '" + key + "' (empty or reserved)");
  s.points.close();
  if (s.normals)
    s.normals->close();
  if (s.confidence)
    s.confidence->close();
  const hsize_t T = static_cast<hsize_t>(frames());
  s.file.write(k_offsets, s.offsets.data(), { T + 1 });
  std::vector<double> time(T);
  for (hsize_t t = 0; t < T; ++t)
    time[t] = s.start_time + double(t) * s.dt;
  s.file.write(k_time, time.data(), { T });
  s.file.set_attribute(
      "format", std::string(k_clouds_kind) + "/" + std::to_string(k_clouds_version));
  s.file.set_number_attribute("dt", s.dt);
  for (const auto& [key, value] : metadata)
    s.file.set_attribute(key, value);
  s.file.close();
  s.atomic.commit();
  s.finished = true;
}

void write_clouds_h5(const std::filesystem::path& path, const capture::PointCloudSequence& clouds,
    const std::map<std::string, std::string>& metadata) {
  clouds.validate(path.string());
  CloudWriter writer(path, clouds.dt, clouds.start_time);
  for (int t = 0; t < clouds.num_frames(); ++t)
    writer.append(clouds.frame(t));
  writer.finish(metadata);
}

capture::PointCloudSequence read_clouds_h5(const std::filesystem::path& path) {
  const h5::File file = h5::File::open(path);
  file.check_format(k_clouds_kind, k_clouds_version, "point-cloud file");
  capture::PointCloudSequence clouds;

  const hsize_t N = shape_of(file, k_points, 2, true, "(N, 3)")[0];
  const hsize_t T1 = shape_of(file, k_offsets, 1, false, "(T+1,)")[0];
  if (T1 < 2)
    file.fail(k_offsets, "needs T + 1 ≥ 2 entries (at least one frame), got " + std::to_string(T1));
  if (file.number_kind(k_offsets) != h5::NumberKind::integer)
    file.fail(k_offsets, "expected an integer dataset");
  const hsize_t T = shape_of(file, k_time, 1, false, "(T,)")[0];
  if (T + 1 != T1)
    file.fail(k_time,
        "has " + std::to_string(T) + " frames but " + k_offsets + " describes "
            + std::to_string(T1 - 1) + " (its " + std::to_string(T1) + " entries are T + 1)");
  const std::vector<double> offsets = file.read_f64(k_offsets);
  clouds.offsets.assign(offsets.size(), 0);
  for (std::size_t t = 0; t < offsets.size(); ++t) {
    // Integer datasets arrive exactly as doubles up to 2⁵³ points.
    if (!(offsets[t] >= 0 && offsets[t] <= double(N)))
      file.fail(k_offsets,
          "entry " + std::to_string(t) + " (" + to_text_exact(offsets[t])
              + ") is outside [0, N = " + std::to_string(N) + "]");
    clouds.offsets[t] = static_cast<Eigen::Index>(offsets[t]);
  }
  clouds.points.resize(static_cast<Eigen::Index>(N), 3);
  file.read(k_points, clouds.points.data());
  if (file.exists(k_normals)) {
    const hsize_t rows = shape_of(file, k_normals, 2, true, "(N, 3)")[0];
    if (rows != N)
      file.fail(k_normals,
          "has " + std::to_string(rows) + " rows but " + k_points + " has " + std::to_string(N));
    clouds.normals.resize(static_cast<Eigen::Index>(N), 3);
    if (N > 0)
      file.read(k_normals, clouds.normals.data());
  }
  if (file.exists(k_confidence)) {
    const hsize_t rows = shape_of(file, k_confidence, 1, false, "(N,)")[0];
    if (rows != N)
      file.fail(k_confidence,
          "has " + std::to_string(rows) + " values but " + k_points + " has " + std::to_string(N));
    clouds.confidence.resize(static_cast<Eigen::Index>(N));
    if (N > 0)
      file.read(k_confidence, clouds.confidence.data());
  }
  clouds.dt = read_dt(file);
  const std::vector<double> time = file.read_f64(k_time);
  clouds.start_time = time.front();
  file.check_even_times(k_time, time, clouds.dt);
  clouds.validate(file.name());
  return clouds;
}

std::map<std::string, std::string> read_clouds_metadata(const std::filesystem::path& path) {
  const h5::File file = h5::File::open(path);
  file.check_format(k_clouds_kind, k_clouds_version, "point-cloud file");
  std::map<std::string, std::string> metadata = file.attributes("/");
  metadata.erase("format");
  metadata.erase("dt");
  return metadata;
}

double read_clouds_noise_sigma(const std::filesystem::path& path) {
  const auto metadata = read_clouds_metadata(path);
  const auto it = metadata.find("noise_sigma");
  if (it == metadata.end())
    return 0;
  try {
    std::size_t used = 0;
    const double sigma = std::stod(it->second, &used);
    if (used == it->second.size() && std::isfinite(sigma) && sigma >= 0)
      return sigma;
  } catch (const std::exception&) { }
  throw InputError(path.string() + ": / attribute 'noise_sigma'",
      "'" + it->second + "' is not a non-negative number (the scanner's accuracy in metres)");
}

bool is_clouds_h5(const std::filesystem::path& path) {
  try {
    const std::optional<std::string> format = h5::File::open(path).attribute("format");
    return format && format->rfind(std::string(k_clouds_kind) + "/", 0) == 0;
  } catch (const InputError&) {
    return false;
  }
}

} // namespace elastolearn::io
