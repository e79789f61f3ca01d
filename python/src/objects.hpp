#pragma once
// The objects the Python module hands out, and the conversions its functions share.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/observe/observation.hpp>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include <map>
#include <string>

namespace elastolearn::python {

namespace py = pybind11;

/// A material: the file's contents (nominal JSON, correction, provenance) and the model parsed
/// from them. `source` names it in messages (a file name, "learned" or the scene's file).
struct Material {
  io::MaterialFile file;
  fem::MaterialModel model;
  std::string source;
};

/// An observation with its file metadata.
struct Observation {
  observe::Observation observation;
  std::map<std::string, std::string> metadata;
};

/// The material of a material file (parsed, errors naming `source`).
Material make_material(io::MaterialFile file, const std::string& source);

/// JSON ↔ Python (through the json module: dicts, lists, numbers, strings, None).
py::object to_python(const nlohmann::json& json);
nlohmann::json to_json(const py::handle& object);

/// A scene given as an elastolearn.Scene or a path (str or os.PathLike), read if a path.
io::SceneFile scene_argument(const py::handle& scene);
/// A material given as an elastolearn.Material or a path to a material file.
Material material_argument(const py::handle& material);
/// A trajectory given as an elastolearn.Trajectory or a path; `source` receives the file name
/// (or "trajectory").
io::TrajectoryData trajectory_argument(const py::handle& trajectory, std::string& source);

/// True if `object` is a str or an os.PathLike; then `path` is its text.
bool is_path(const py::handle& object, std::string& path);

void bind_files(py::module_& m);
void bind_scene(py::module_& m);
void bind_runs(py::module_& m);

} // namespace elastolearn::python
