#include "objects.hpp"

#include <elastolearn/core/error.hpp>

namespace elastolearn::python {

namespace {

/// `object` as a T (copied), or a TypeError naming the argument and what it accepts.
template <typename T>
T cast_argument(const py::handle& object, const char* name, const char* expected) {
  try {
    return object.cast<const T&>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string(name) + ": expected " + expected + ", got "
        + std::string(py::str(py::type::of(object).attr("__name__"))));
  }
}

} // namespace

Material make_material(io::MaterialFile file, const std::string& source) {
  Material m;
  m.model = io::material_model(file, source);
  m.file = std::move(file);
  m.source = source;
  return m;
}

py::object to_python(const nlohmann::json& json) {
  return py::module_::import("json").attr("loads")(json.dump());
}

nlohmann::json to_json(const py::handle& object) {
  const std::string text = py::str(py::module_::import("json").attr("dumps")(object));
  return nlohmann::json::parse(text);
}

bool is_path(const py::handle& object, std::string& path) {
  if (py::isinstance<py::str>(object)) {
    path = object.cast<std::string>();
    return true;
  }
  const py::object path_like = py::module_::import("os").attr("PathLike");
  if (py::isinstance(object, path_like)) {
    path = py::str(py::module_::import("os").attr("fspath")(object)).cast<std::string>();
    return true;
  }
  return false;
}

io::SceneFile scene_argument(const py::handle& scene) {
  std::string path;
  if (is_path(scene, path))
    return io::read_scene_file(path);
  return cast_argument<io::SceneFile>(scene, "scene", "an elastolearn.Scene or a scene file path");
}

Material material_argument(const py::handle& material) {
  std::string path;
  if (is_path(material, path))
    return make_material(io::read_material_file(path), path);
  return cast_argument<Material>(
      material, "material", "an elastolearn.Material or a material file path");
}

io::TrajectoryData trajectory_argument(const py::handle& trajectory, std::string& source) {
  if (is_path(trajectory, source))
    return io::read_trajectory_h5(source);
  source = "trajectory";
  return cast_argument<io::TrajectoryData>(
      trajectory, "trajectory", "an elastolearn.Trajectory or a trajectory file path");
}

} // namespace elastolearn::python
