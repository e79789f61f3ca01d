#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/hdf5_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>

#include <cmath>
#include <optional>

namespace elastolearn::io {

namespace {

constexpr const char* k_trajectory_kind = "elastolearn-trajectory";
constexpr int k_trajectory_version = 1;
constexpr hsize_t k_any = ~hsize_t(0);

/// Throws InputError("<file>: <dataset>", "<frame prefix>non-finite value ...") if any of the
/// rows×3 values is NaN or infinite.
void check_finite(const std::string& where, const double* values, Eigen::Index rows,
    const std::string& frame_prefix = "") {
  for (Eigen::Index i = 0; i < rows * 3; ++i) {
    if (!std::isfinite(values[i])) {
      throw InputError(where,
          frame_prefix + "non-finite value " + to_text_exact(values[i]) + " at vertex "
              + std::to_string(i / 3) + " (component " + std::to_string(i % 3) + ")");
    }
  }
}

/// Throws InputError if an index of the rows×cols table lies outside [0, n).
void check_indices(
    const std::string& where, const int* indices, Eigen::Index rows, int cols, Eigen::Index n) {
  for (Eigen::Index i = 0; i < rows * cols; ++i) {
    if (indices[i] < 0 || indices[i] >= n) {
      throw InputError(where,
          "vertex index " + std::to_string(indices[i]) + " in row " + std::to_string(i / cols)
              + " is out of range [0, " + std::to_string(n) + ")");
    }
  }
}

/// Throws unless `time` is finite and later than `previous` (if any).
void check_time(const std::string& where, long frame, double time, std::optional<double> previous) {
  if (!std::isfinite(time)) {
    throw InputError(
        where, "frame " + std::to_string(frame) + ": non-finite time " + to_text_exact(time));
  }
  if (previous && !(time > *previous)) {
    throw InputError(where,
        "frame " + std::to_string(frame) + ": time " + to_text_exact(time)
            + " does not increase (previous frame at " + to_text_exact(*previous) + ")");
  }
}

/// Element tables that may accompany the vertices, with their HDF5 names.
template <typename Table>
void check_table(const std::string& file, const char* dataset, const Table& table, Eigen::Index n) {
  check_indices(file + ": " + dataset, table.data(), table.rows(), Table::ColsAtCompileTime, n);
}

} // namespace

// --- TrajectoryWriter ------------------------------------------------------------------------

struct TrajectoryWriter::Impl {
  Impl(const std::filesystem::path& path, Eigen::Index vertices)
      : atomic(path)
      , name(path.string())
      , file(h5::File::create(atomic.temp_path(), name))
      , n(vertices)
      , positions(file, "/positions", { hsize_t(n), 3 })
      , time(file, "/time", {}) { }

  AtomicFile atomic; ///< destroyed last: removes the temporary file unless committed
  std::string name;
  h5::File file;
  Eigen::Index n;
  h5::AppendableDataset positions;
  h5::AppendableDataset time;
  std::optional<h5::AppendableDataset> velocities;
  std::optional<double> last_time;
  long frames = 0;
  bool finished = false;
  bool failed = false; ///< an HDF5 write failed: datasets may disagree, never publish
  bool keep = false;
  std::map<std::string, std::string> partial_metadata;
  Positions scratch_x, scratch_v;

  std::string where(const char* dataset) const { return name + ": " + dataset; }

  /// Contiguous row-major data of `x`, copied into `scratch` only if `x` is strided.
  static const double* contiguous(ConstRef<Positions> x, Positions& scratch) {
    if (x.rows() == 0 || x.outerStride() == 3)
      return x.data();
    scratch = x;
    return scratch.data();
  }

  /// Validate the whole frame first, then write it (time last: its length counts the frames).
  void append(double t, ConstRef<Positions> x, const Eigen::Ref<const Positions>* v) {
    ELASTOLEARN_CHECK(!finished, "TrajectoryWriter::append after finish");
    if (failed)
      throw InputError(name, "an earlier write failed; the trajectory cannot continue");
    const std::string frame = "frame " + std::to_string(frames) + ": ";
    check_time(where("/time"), frames, t, last_time);
    if (x.rows() != n) {
      throw InputError(where("/positions"),
          frame + "has " + std::to_string(x.rows()) + " vertices, expected " + std::to_string(n));
    }
    if (v && v->rows() != n) {
      throw InputError(where("/velocities"),
          frame + "has " + std::to_string(v->rows()) + " vertices, expected " + std::to_string(n));
    }
    if (frames > 0 && (v != nullptr) != velocities.has_value()) {
      throw InputError(where("/velocities"),
          frame
              + (v ? "has velocities but earlier frames have none"
                   : "has no velocities but earlier frames have them"));
    }
    const double* x_data = contiguous(x, scratch_x);
    const double* v_data = v ? contiguous(*v, scratch_v) : nullptr;
    check_finite(where("/positions"), x_data, n, frame);
    if (v_data)
      check_finite(where("/velocities"), v_data, n, frame);
    try {
      if (v_data && !velocities)
        velocities.emplace(file, "/velocities", h5::Shape { hsize_t(n), 3 });
      positions.append(x_data);
      if (v_data)
        velocities->append(v_data);
      time.append(&t);
    } catch (...) {
      failed = true;
      throw;
    }
    last_time = t;
    ++frames;
  }

  void finish(const std::map<std::string, std::string>& metadata) {
    ELASTOLEARN_CHECK(!finished, "TrajectoryWriter::finish called twice");
    if (failed)
      throw InputError(name, "an earlier write failed; nothing to finish");
    for (const auto& [key, value] : metadata) {
      if (key.empty() || key == "format") {
        throw InputError(name, "invalid metadata key '" + key + "' (empty or reserved)");
      }
    }
    try {
      file.set_attribute(
          "format", std::string(k_trajectory_kind) + "/" + std::to_string(k_trajectory_version));
      for (const auto& [key, value] : metadata)
        file.set_attribute(key, value);
      positions.close();
      time.close();
      if (velocities)
        velocities->close();
      file.close();
      atomic.commit();
    } catch (...) {
      failed = true;
      throw;
    }
    finished = true;
  }
};

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& path,
    ConstRef<Positions> rest_positions, const Tets& tets, const Edges& edges, const Faces& faces) {
  const std::string name = path.string();
  const Eigen::Index n = rest_positions.rows();
  if (n == 0)
    throw InputError(name + ": /rest_positions", "no vertices");
  const Positions rest = rest_positions; // contiguous copy (rest data is written once)
  check_finite(name + ": /rest_positions", rest.data(), n);
  check_table(name, "/tets", tets, n);
  check_table(name, "/edges", edges, n);
  check_table(name, "/faces", faces, n);
  m_impl = std::make_unique<Impl>(path, n);
  h5::File& file = m_impl->file;
  try {
    file.write("/rest_positions", rest.data(), { hsize_t(n), 3 });
    if (tets.rows() > 0)
      file.write("/tets", tets.data(), { hsize_t(tets.rows()), 4 });
    if (edges.rows() > 0)
      file.write("/edges", edges.data(), { hsize_t(edges.rows()), 2 });
    if (faces.rows() > 0)
      file.write("/faces", faces.data(), { hsize_t(faces.rows()), 3 });
  } catch (...) {
    m_impl->failed = true;
    throw;
  }
}

TrajectoryWriter::~TrajectoryWriter() {
  if (!m_impl || m_impl->finished)
    return;
  if (m_impl->keep && !m_impl->failed) {
    try {
      m_impl->finish(m_impl->partial_metadata);
    } catch (...) {
      // Nothing more can be done while unwinding; the temporary file is removed below.
    }
  }
  // ~Impl closes the datasets and the file, then ~AtomicFile removes the uncommitted temp file.
}

TrajectoryWriter::TrajectoryWriter(TrajectoryWriter&&) noexcept = default;
TrajectoryWriter& TrajectoryWriter::operator=(TrajectoryWriter&&) noexcept = default;

void TrajectoryWriter::append(double time, ConstRef<Positions> positions) {
  m_impl->append(time, positions, nullptr);
}

void TrajectoryWriter::append(
    double time, ConstRef<Positions> positions, ConstRef<Positions> velocities) {
  m_impl->append(time, positions, &velocities);
}

void TrajectoryWriter::finish(const std::map<std::string, std::string>& metadata) {
  m_impl->finish(metadata);
}

void TrajectoryWriter::keep_partial(std::map<std::string, std::string> metadata) {
  metadata.emplace("status", "partial");
  m_impl->keep = true;
  m_impl->partial_metadata = std::move(metadata);
}

long TrajectoryWriter::frames() const {
  return m_impl->frames;
}

const std::filesystem::path& TrajectoryWriter::path() const {
  return m_impl->atomic.target();
}

void write_trajectory_h5(const std::filesystem::path& path, const TrajectoryData& data) {
  const std::string name = path.string();
  if (data.time.size() != data.positions.size()) {
    throw InputError(name,
        std::to_string(data.positions.size()) + " position frames but "
            + std::to_string(data.time.size()) + " times");
  }
  if (!data.velocities.empty() && data.velocities.size() != data.positions.size()) {
    throw InputError(name,
        std::to_string(data.positions.size()) + " position frames but "
            + std::to_string(data.velocities.size()) + " velocity frames");
  }
  TrajectoryWriter writer(path, data.rest_positions, data.tets, data.edges, data.faces);
  for (std::size_t t = 0; t < data.positions.size(); ++t) {
    if (data.velocities.empty()) {
      writer.append(data.time[t], data.positions[t]);
    } else {
      writer.append(data.time[t], data.positions[t], data.velocities[t]);
    }
  }
  writer.finish(data.metadata);
}

// --- reading ---------------------------------------------------------------------------------

namespace {

/// Check a dataset's shape against `expected` (k_any matches any extent); `pattern` describes it
/// symbolically for the message, e.g. "(T, n, 3)".
h5::Shape require_shape(const h5::File& file, const std::string& dataset, const h5::Shape& expected,
    const std::string& pattern) {
  const h5::Shape shape = file.shape(dataset);
  bool ok = shape.size() == expected.size();
  for (std::size_t i = 0; ok && i < shape.size(); ++i) {
    ok = expected[i] == k_any || expected[i] == shape[i];
  }
  if (!ok) {
    std::string wanted = pattern;
    bool concrete = true;
    for (hsize_t e : expected)
      concrete = concrete && e != k_any;
    if (concrete && pattern != h5::shape_string(expected)) {
      wanted += " = " + h5::shape_string(expected);
    }
    file.fail(dataset, "expected shape " + wanted + ", got " + h5::shape_string(shape));
  }
  return shape;
}

void check_format(const h5::File& file) {
  file.check_format(k_trajectory_kind, k_trajectory_version, "trajectory");
}

template <typename Table>
Table read_table(const h5::File& file, const char* dataset, Eigen::Index n) {
  constexpr int cols = Table::ColsAtCompileTime;
  Table table;
  if (!file.exists(dataset))
    return table;
  const h5::Shape shape
      = require_shape(file, dataset, { k_any, hsize_t(cols) }, "(m, " + std::to_string(cols) + ")");
  table.resize(Eigen::Index(shape[0]), cols);
  file.read(dataset, table.data());
  check_table(file.name(), dataset, table, n);
  return table;
}

/// Check that `dataset` has shape (frames, n, 3).
void require_frames_shape(
    const h5::File& file, const char* dataset, hsize_t frames, Eigen::Index n) {
  const h5::Shape shape = file.shape(dataset);
  if (shape.size() == 3 && shape[0] != frames && shape[1] == hsize_t(n) && shape[2] == 3) {
    file.fail(dataset,
        "has " + std::to_string(shape[0]) + " frames but /time has " + std::to_string(frames));
  }
  require_shape(file, dataset, { frames, hsize_t(n), 3 }, "(T, n, 3)");
}

/// Read a (T, n, 3) dataset frame by frame, checking every value is finite.
std::vector<Positions> read_frames(
    const h5::File& file, const char* dataset, hsize_t frames, Eigen::Index n) {
  require_frames_shape(file, dataset, frames, n);
  const h5::Dataset ds = file.dataset(dataset); // open once: its chunk cache serves every frame
  std::vector<Positions> out(frames, Positions(n, 3));
  for (hsize_t t = 0; t < frames; ++t) {
    ds.read(out[t].data(), t, 1);
    check_finite(
        file.name() + ": " + dataset, out[t].data(), n, "frame " + std::to_string(t) + ": ");
  }
  return out;
}

} // namespace

namespace {

/// Rest positions and times of an opened trajectory, format checked.
struct TrajectoryHeader {
  Positions rest_positions;
  std::vector<double> time;
  Eigen::Index vertices() const { return rest_positions.rows(); }
};

TrajectoryHeader read_header(const h5::File& file) {
  check_format(file);
  TrajectoryHeader header;
  const h5::Shape rest_shape = require_shape(file, "/rest_positions", { k_any, 3 }, "(n, 3)");
  const Eigen::Index n = Eigen::Index(rest_shape[0]);
  if (n == 0)
    file.fail("/rest_positions", "no vertices");
  header.rest_positions.resize(n, 3);
  file.read("/rest_positions", header.rest_positions.data());
  check_finite(file.name() + ": /rest_positions", header.rest_positions.data(), n);

  const h5::Shape time_shape = require_shape(file, "/time", { k_any }, "(T,)");
  header.time.resize(time_shape[0]);
  file.read("/time", header.time.data());
  for (std::size_t t = 0; t < header.time.size(); ++t) {
    check_time(file.name() + ": /time", long(t), header.time[t],
        t ? std::optional<double>(header.time[t - 1]) : std::nullopt);
  }
  return header;
}

/// Frame `index` of the (T, n, 3) dataset, shape and finiteness checked.
Positions read_one_frame(
    const h5::File& file, const char* dataset, hsize_t frames, Eigen::Index n, hsize_t index) {
  require_frames_shape(file, dataset, frames, n);
  Positions out(n, 3);
  file.dataset(dataset).read(out.data(), index, 1);
  check_finite(
      file.name() + ": " + dataset, out.data(), n, "frame " + std::to_string(index) + ": ");
  return out;
}

} // namespace

TrajectoryData read_trajectory_h5(const std::filesystem::path& path) {
  const h5::File file = h5::File::open(path);
  TrajectoryHeader header = read_header(file);
  const Eigen::Index n = header.vertices();
  const hsize_t frames = header.time.size();
  TrajectoryData data;
  data.rest_positions = std::move(header.rest_positions);
  data.time = std::move(header.time);

  data.positions = read_frames(file, "/positions", frames, n);
  if (file.exists("/velocities"))
    data.velocities = read_frames(file, "/velocities", frames, n);
  data.tets = read_table<Tets>(file, "/tets", n);
  data.edges = read_table<Edges>(file, "/edges", n);
  data.faces = read_table<Faces>(file, "/faces", n);

  data.metadata = file.attributes("/");
  data.metadata.erase("format");
  return data;
}

long read_trajectory_frame_count(const std::filesystem::path& path) {
  const h5::File file = h5::File::open(path);
  check_format(file);
  return long(require_shape(file, "/time", { k_any }, "(T,)")[0]);
}

TrajectoryFrame read_trajectory_frame(const std::filesystem::path& path, long index) {
  const h5::File file = h5::File::open(path);
  TrajectoryHeader header = read_header(file);
  const long frames = long(header.time.size());
  if (index < 0 || index >= frames) {
    file.fail("/positions",
        "frame " + std::to_string(index) + " is out of range [0, " + std::to_string(frames) + ")");
  }
  TrajectoryFrame out;
  out.index = index;
  out.frames = frames;
  out.time = header.time[std::size_t(index)];
  const Eigen::Index n = header.vertices();
  out.positions = read_one_frame(file, "/positions", hsize_t(frames), n, hsize_t(index));
  if (file.exists("/velocities"))
    out.velocities = read_one_frame(file, "/velocities", hsize_t(frames), n, hsize_t(index));
  out.rest_positions = std::move(header.rest_positions);
  return out;
}

} // namespace elastolearn::io
