// Trajectories and observations: the in-memory objects and their HDF5 files.
#include "arrays.hpp"
#include "objects.hpp"

#include <elastolearn/core/error.hpp>
#include <elastolearn/io/observation_file.hpp>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>

namespace elastolearn::python {

namespace {

Eigen::Index vertex_count(const std::vector<Positions>& frames, Eigen::Index fallback) {
  return frames.empty() ? fallback : frames.front().rows();
}

io::TrajectoryData make_trajectory(const DoubleArray& rest_positions, const DoubleArray& positions,
    const DoubleArray& time, const std::optional<IntArray>& tets,
    const std::optional<DoubleArray>& velocities,
    const std::map<std::string, std::string>& metadata) {
  io::TrajectoryData t;
  t.rest_positions = to_positions(rest_positions, "rest_positions");
  t.positions = to_frames(positions, "positions");
  t.time = to_doubles(time, "time");
  if (tets)
    t.tets = to_indices<4>(*tets, "tets");
  if (velocities)
    t.velocities = to_frames(*velocities, "velocities");
  t.metadata = metadata;
  return t;
}

Observation make_observation(const IntArray& vertex_ids, const DoubleArray& positions, double dt,
    double start_time, const std::map<std::string, std::string>& metadata,
    const std::optional<MaskArray>& valid) {
  Observation o;
  o.observation.vertex_ids = to_ints(vertex_ids, "vertex_ids");
  o.observation.positions = to_frames(positions, "positions");
  if (valid) {
    o.observation.valid
        = to_mask(*valid, o.observation.num_frames(), o.observation.num_observed(), "valid");
  }
  o.observation.dt = dt;
  o.observation.start_time = start_time;
  o.observation.validate("observation");
  o.metadata = metadata;
  return o;
}

} // namespace

void bind_files(py::module_& m) {
  py::class_<io::TrajectoryData>(m, "Trajectory",
      "A recorded motion: rest positions (n, 3), positions and velocities (T, n, 3), times (T,), "
      "tets (m, 4) and string metadata; the HDF5 trajectory file in memory "
      "(docs/file_formats.md). Arrays are copies.")
      .def(py::init(&make_trajectory), py::arg("rest_positions"), py::arg("positions"),
          py::arg("time"), py::arg("tets") = py::none(), py::arg("velocities") = py::none(),
          py::arg("metadata") = std::map<std::string, std::string> {})
      .def_property_readonly(
          "rest_positions", [](const io::TrajectoryData& t) { return to_array(t.rest_positions); })
      .def_property_readonly("positions",
          [](const io::TrajectoryData& t) {
            return to_array(t.positions, vertex_count(t.positions, t.rest_positions.rows()));
          })
      .def_property_readonly("velocities",
          [](const io::TrajectoryData& t) -> py::object {
            if (t.velocities.empty())
              return py::none();
            return to_array(t.velocities, t.rest_positions.rows());
          })
      .def_property_readonly("time", [](const io::TrajectoryData& t) { return to_array(t.time); })
      .def_property_readonly("tets", [](const io::TrajectoryData& t) { return to_array(t.tets); })
      .def_property_readonly("faces", [](const io::TrajectoryData& t) { return to_array(t.faces); })
      .def_readwrite("metadata", &io::TrajectoryData::metadata)
      .def_property_readonly("num_frames",
          [](const io::TrajectoryData& t) { return static_cast<int>(t.positions.size()); })
      .def_property_readonly("num_vertices",
          [](const io::TrajectoryData& t) { return static_cast<int>(t.rest_positions.rows()); })
      .def(
          "write",
          [](const io::TrajectoryData& t, const std::filesystem::path& path) {
            io::write_trajectory_h5(path, t);
          },
          py::arg("path"), "Write the HDF5 trajectory file (atomically).")
      .def("__repr__", [](const io::TrajectoryData& t) {
        return "<elastolearn.Trajectory: " + std::to_string(t.positions.size()) + " frames of "
            + std::to_string(t.rest_positions.rows()) + " vertices>";
      });
  m.def(
      "read_trajectory",
      [](const std::filesystem::path& path) { return io::read_trajectory_h5(path); },
      py::arg("path"), "Read and validate an HDF5 trajectory file.");
  m.def(
      "write_trajectory",
      [](const std::filesystem::path& path, const io::TrajectoryData& t) {
        io::write_trajectory_h5(path, t);
      },
      py::arg("path"), py::arg("trajectory"), "Write an HDF5 trajectory file (atomically).");

  py::class_<Observation>(m, "Observation",
      "Observed positions of k mesh vertices over T frames spaced dt apart: vertex_ids (k,), "
      "positions (T, k, 3), dt, start_time, string metadata and valid (T, k): False where a "
      "marker was lost (its position means nothing, NaN in files) (docs/observations.md).")
      .def(py::init(&make_observation), py::arg("vertex_ids"), py::arg("positions"), py::arg("dt"),
          py::arg("start_time") = 0.0, py::arg("metadata") = std::map<std::string, std::string> {},
          py::arg("valid") = py::none())
      .def_property_readonly(
          "vertex_ids", [](const Observation& o) { return to_array(o.observation.vertex_ids); })
      .def_property_readonly("positions",
          [](const Observation& o) {
            return to_array(o.observation.positions, o.observation.num_observed());
          })
      .def_property_readonly(
          "valid",
          [](const Observation& o) {
            return to_array(
                o.observation.valid, o.observation.num_frames(), o.observation.num_observed());
          },
          "(T, k) bool: True where the marker was seen")
      .def_property_readonly(
          "num_valid", [](const Observation& o) { return o.observation.num_valid(); })
      .def_property_readonly("dt", [](const Observation& o) { return o.observation.dt; })
      .def_property_readonly(
          "start_time", [](const Observation& o) { return o.observation.start_time; })
      .def_property_readonly("time",
          [](const Observation& o) {
            std::vector<double> time(o.observation.positions.size());
            for (size_t t = 0; t < time.size(); ++t)
              time[t] = o.observation.start_time + double(t) * o.observation.dt;
            return to_array(time);
          })
      .def_property_readonly(
          "num_frames", [](const Observation& o) { return o.observation.num_frames(); })
      .def_property_readonly(
          "num_observed", [](const Observation& o) { return o.observation.num_observed(); })
      .def_readwrite("metadata", &Observation::metadata)
      .def(
          "write",
          [](const Observation& o, const std::filesystem::path& path) {
            io::write_observation_h5(path, o.observation, o.metadata);
          },
          py::arg("path"), "Write the HDF5 observation file (atomically).")
      .def("__repr__", [](const Observation& o) {
        return "<elastolearn.Observation: " + std::to_string(o.observation.num_observed())
            + " vertices over " + std::to_string(o.observation.num_frames()) + " frames>";
      });
  m.def(
      "read_observations",
      [](const std::filesystem::path& path) {
        return Observation { io::read_observation_h5(path), io::read_observation_metadata(path) };
      },
      py::arg("path"), "Read and validate an HDF5 observation file.");
  m.def(
      "write_observations",
      [](const std::filesystem::path& path, const Observation& o) {
        io::write_observation_h5(path, o.observation, o.metadata);
      },
      py::arg("path"), py::arg("observation"), "Write an HDF5 observation file (atomically).");
}

} // namespace elastolearn::python
