#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/hdf5_file.hpp>
#include <elastolearn/io/observation_file.hpp>

#include <charconv>
#include <cmath>

namespace elastolearn::io {

namespace {

constexpr const char* k_observation_kind = "elastolearn-observation";
/// Version 2 adds the optional /observed/valid; a file without it is written as version 1, which
/// every reader reads. A file with it says 2, so that a reader that would ignore the mask (and
/// take lost positions for data) refuses it instead.
constexpr int k_observation_version = 2;
const std::string k_ids = "/observed/vertex_ids";
const std::string k_positions = "/observed/positions";
const std::string k_valid = "/observed/valid";
const std::string k_time = "/time";

void check_format(const h5::File& file) {
  file.check_format(k_observation_kind, k_observation_version, "observation");
}

/// The optional /observed/valid: T × k integers, each 0 (lost) or 1 (seen); empty if absent.
observe::ValidityMask read_valid(const h5::File& file, hsize_t frames, hsize_t points) {
  if (!file.exists(k_valid))
    return {};
  const h5::Dataset dataset = file.dataset(k_valid);
  if (dataset.number_kind() != h5::NumberKind::integer)
    file.fail(k_valid,
        "expected integers 0 (lost) or 1 (seen), e.g. numpy uint8 (from a boolean array: "
        "valid.astype(numpy.uint8))");
  const h5::Shape shape = dataset.shape();
  if (shape.size() != 2 || shape[0] != frames || shape[1] != points) {
    file.fail(k_valid,
        "expected shape (" + std::to_string(frames) + ", " + std::to_string(points)
            + ") (frames, observed vertices) like " + k_positions + ", got "
            + h5::shape_string(shape));
  }
  std::vector<int> values(frames * points);
  dataset.read(values.data());
  observe::ValidityMask valid(static_cast<Eigen::Index>(frames), static_cast<Eigen::Index>(points));
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (values[i] != 0 && values[i] != 1) {
      file.fail(k_valid,
          "frame " + std::to_string(i / points) + ", entry " + std::to_string(i % points)
              + ": value " + std::to_string(values[i]) + " (expected 1 = seen or 0 = lost)");
    }
    valid.data()[i] = static_cast<std::uint8_t>(values[i]);
  }
  return valid;
}

/// Shape of `dataset`, which must have `rank` dimensions; `pattern` names them for the message.
h5::Shape shape_of_rank(const h5::File& file, const std::string& dataset, std::size_t rank,
    const std::string& pattern) {
  const h5::Shape shape = file.shape(dataset);
  if (shape.size() != rank || (rank == 3 && shape[2] != 3)) {
    file.fail(dataset, "expected shape " + pattern + ", got " + h5::shape_string(shape));
  }
  return shape;
}

double read_dt(const h5::File& file) {
  return file.positive_attribute("dt", "the time between frames, in seconds");
}

} // namespace

void write_observation_h5(const std::filesystem::path& path, const observe::Observation& obs,
    const std::map<std::string, std::string>& metadata) {
  const std::string name = path.string();
  obs.validate(name);
  for (const auto& [key, value] : metadata)
    if (key.empty() || key == "format" || key == "dt")
      throw InputError(name, "invalid metadata key '" + key + "' (empty or reserved)");
  const hsize_t T = static_cast<hsize_t>(obs.num_frames());
  const hsize_t k = static_cast<hsize_t>(obs.num_observed());
  std::vector<double> positions(T * k * 3);
  std::vector<double> time(T);
  for (hsize_t t = 0; t < T; ++t) {
    std::copy_n(obs.positions[t].data(), k * 3, positions.begin() + t * k * 3);
    time[t] = obs.start_time + double(t) * obs.dt;
  }
  AtomicFile atomic(path);
  h5::File file = h5::File::create(atomic.temp_path(), name);
  file.write(k_ids, obs.vertex_ids.data(), { k });
  file.write(k_positions, positions.data(), { T, k, 3 });
  file.write(k_time, time.data(), { T });
  if (obs.valid.size() != 0)
    file.write(k_valid, obs.valid.data(), { T, k });
  file.set_attribute("format",
      std::string(k_observation_kind) + "/"
          + std::to_string(obs.valid.size() != 0 ? k_observation_version : 1));
  file.set_number_attribute("dt", obs.dt);
  for (const auto& [key, value] : metadata)
    file.set_attribute(key, value);
  file.close();
  atomic.commit();
}

observe::Observation read_observation_h5(const std::filesystem::path& path) {
  const h5::File file = h5::File::open(path);
  check_format(file);
  observe::Observation obs;

  const hsize_t k = shape_of_rank(file, k_ids, 1, "(k,)")[0];
  obs.vertex_ids = file.read_i32(k_ids);

  const h5::Shape shape = shape_of_rank(file, k_positions, 3, "(T, k, 3)");
  if (shape[1] != k) {
    file.fail(k_positions,
        "has " + std::to_string(shape[1]) + " points per frame but " + k_ids + " lists "
            + std::to_string(k) + " vertices");
  }
  const hsize_t T = shape[0];
  const h5::Shape time_shape = shape_of_rank(file, k_time, 1, "(T,)");
  if (time_shape[0] != T) {
    file.fail(k_time,
        "has " + std::to_string(time_shape[0]) + " times but " + k_positions + " has "
            + std::to_string(T) + " frames");
  }
  obs.valid = read_valid(file, T, k);
  const std::vector<double> values = file.read_f64(k_positions);
  obs.positions.assign(T, Positions(Eigen::Index(k), 3));
  for (hsize_t t = 0; t < T; ++t)
    std::copy_n(values.begin() + t * k * 3, k * 3, obs.positions[t].data());

  obs.dt = read_dt(file);
  const std::vector<double> time = file.read_f64(k_time);
  if (!time.empty())
    obs.start_time = time.front();
  file.check_even_times(k_time, time, obs.dt);
  obs.validate(file.name());
  return obs;
}

std::map<std::string, std::string> read_observation_metadata(const std::filesystem::path& path) {
  const h5::File file = h5::File::open(path);
  check_format(file);
  std::map<std::string, std::string> metadata = file.attributes("/");
  metadata.erase("format");
  metadata.erase("dt");
  return metadata;
}

bool is_observation_h5(const std::filesystem::path& path) {
  try {
    const std::optional<std::string> format = h5::File::open(path).attribute("format");
    return format && format->rfind(std::string(k_observation_kind) + "/", 0) == 0;
  } catch (const InputError&) {
    return false;
  }
}

std::vector<int> read_vertex_id_list(const std::filesystem::path& path) {
  const std::string text = read_text_file(path);
  std::vector<int> ids;
  std::istringstream lines(text);
  std::string line;
  for (int line_number = 1; std::getline(lines, line); ++line_number) {
    line = line.substr(0, line.find('#'));
    for (char& c : line) {
      if (c == ',' || c == '\t' || c == '\r')
        c = ' ';
    }
    std::istringstream tokens(line);
    std::string token;
    while (tokens >> token) {
      int id = -1;
      const auto result = std::from_chars(token.data(), token.data() + token.size(), id);
      if (result.ec != std::errc() || result.ptr != token.data() + token.size() || id < 0) {
        throw InputError(path.string() + ":" + std::to_string(line_number),
            "'" + token + "' is not a vertex id (a non-negative integer)");
      }
      ids.push_back(id);
    }
  }
  if (ids.empty())
    throw InputError(path.string(), "no vertex ids in the file");
  return ids;
}

} // namespace elastolearn::io
