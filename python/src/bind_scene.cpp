// Scenes (elastolearn-scene/1) and materials (the nominal model plus a learned correction):
// loading, their properties, and a material's principal stress at given stretches.
#include "arrays.hpp"
#include "objects.hpp"

#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <optional>

namespace elastolearn::python {

namespace {

/// P̂(σ) + N(σ, σ̇) per row of `stretches` (m, 3), rates (m, 3) or zero. Each row is evaluated
/// with its stretches sorted descending (rates permuted alike), the order the library's models
/// and corrections are written in, and returned in the row's own order (P̂ and N are symmetric).
py::array_t<double> principal_stress(
    const Material& m, const DoubleArray& stretches, const std::optional<DoubleArray>& rates) {
  const Positions s = to_positions(stretches, "stretches");
  Positions r = Positions::Zero(s.rows(), 3);
  if (rates) {
    r = to_positions(*rates, "stretch_rates");
    if (r.rows() != s.rows())
      throw InputError("stretch_rates",
          "has " + std::to_string(r.rows()) + " rows but stretches has "
              + std::to_string(s.rows()));
  }
  Positions out(s.rows(), 3);
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    std::array<int, 3> order { 0, 1, 2 };
    std::sort(order.begin(), order.end(), [&](int a, int b) { return s(i, a) > s(i, b); });
    Vec3 sorted, sorted_rates;
    for (int k = 0; k < 3; ++k) {
      sorted[k] = s(i, order[k]);
      sorted_rates[k] = r(i, order[k]);
    }
    if (!sorted.allFinite() || !sorted_rates.allFinite())
      throw InputError("stretches", "row " + std::to_string(i) + " is not finite");
    const material::CorrectedStress p = material::corrected_principal_stress(
        *m.model.elastic, m.model.correction.get(), sorted, sorted_rates);
    for (int k = 0; k < 3; ++k)
      out(i, order[k]) = p.stress[k];
  }
  return to_array(out);
}

/// Ψ(σ) of the nominal elastic model per row of `stretches` (m, 3).
py::array_t<double> energy(const Material& m, const DoubleArray& stretches) {
  const Positions s = to_positions(stretches, "stretches");
  std::vector<double> out(static_cast<size_t>(s.rows()));
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    Vec3 sorted = s.row(i).transpose();
    std::sort(sorted.data(), sorted.data() + 3, std::greater<>());
    out[static_cast<size_t>(i)] = m.model.elastic->energy(sorted);
  }
  return to_array(out);
}

Material scene_material(const io::SceneFile& f) {
  Material m;
  m.file.material = f.nominal_material;
  m.file.correction = f.scene.material.correction;
  m.file.training_stretches = f.material_training_stretches;
  m.model = f.scene.material;
  m.source = f.path.empty() ? std::string("scene") : f.path.string();
  return m;
}

io::SceneFile scene_from_json(
    const py::handle& json, const std::filesystem::path& base_dir, const std::string& name) {
  const nlohmann::json j = py::isinstance<py::str>(json)
      ? nlohmann::json::parse(json.cast<std::string>(), nullptr, false)
      : to_json(json);
  if (j.is_discarded())
    throw InputError(name, "is not valid JSON");
  return io::parse_scene(j, name, base_dir);
}

} // namespace

void bind_scene(py::module_& m) {
  py::class_<io::SceneFile>(m, "Scene",
      "A scene (elastolearn-scene/1, docs/scene_format.md): mesh, material, boundary "
      "conditions, time step and frame count. Load with Scene.load(path) or Scene.from_json().")
      .def_static(
          "load", [](const std::filesystem::path& path) { return io::read_scene_file(path); },
          py::arg("path"), "Read and validate a scene file.")
      .def_static("from_json", &scene_from_json, py::arg("json"),
          py::arg("base_dir") = std::filesystem::path("."), py::arg("name") = "scene",
          "A scene from a JSON text or a dict; relative paths resolve against base_dir, "
          "messages name `name`.")
      .def_property(
          "name", [](const io::SceneFile& f) { return f.scene.name; },
          [](io::SceneFile& f, const std::string& v) { f.scene.name = v; })
      .def_property_readonly("path", [](const io::SceneFile& f) { return f.path; })
      .def_property_readonly(
          "num_vertices", [](const io::SceneFile& f) { return f.scene.mesh.num_vertices(); })
      .def_property_readonly(
          "num_tets", [](const io::SceneFile& f) { return f.scene.mesh.num_tets(); })
      .def_property_readonly("rest_positions",
          [](const io::SceneFile& f) { return to_array(f.scene.mesh.rest_positions()); })
      .def_property_readonly(
          "tets", [](const io::SceneFile& f) { return to_array(f.scene.mesh.tets()); })
      .def_property_readonly("surface_faces",
          [](const io::SceneFile& f) { return to_array(f.scene.mesh.surface_faces()); })
      .def_property_readonly("surface_vertices",
          [](const io::SceneFile& f) { return to_array(f.scene.mesh.surface_vertices()); })
      .def_property_readonly(
          "size", [](const io::SceneFile& f) { return f.scene.mesh.bounding_box_diagonal(); },
          "rest bounding-box diagonal [m] (errors in % are relative to it)")
      .def_property_readonly("dt", [](const io::SceneFile& f) { return f.scene.dt; })
      .def_property(
          "frames", [](const io::SceneFile& f) { return f.scene.frames; },
          [](io::SceneFile& f, int frames) {
            if (frames < 1)
              throw InputError("frames", "must be at least 1, got " + std::to_string(frames));
            f.scene.frames = frames;
          },
          "number of steps (a trajectory has frames + 1 states)")
      .def_property(
          "linear_solver",
          [](const io::SceneFile& f) { return sim::to_string(f.scene.linear_solver); },
          [](io::SceneFile& f, const std::string& v) {
            f.scene.linear_solver = sim::linear_solver_type_from_string(v);
          },
          "cholmod | cg | eigen-ldlt")
      .def_property(
          "material", [](const io::SceneFile& f) { return scene_material(f); },
          [](io::SceneFile& f, const Material& material) {
            f.scene.material = material.model;
            f.nominal_material = material.file.material;
            f.material_training_stretches = material.file.training_stretches;
          },
          "the scene's material (setting it replaces the material, as simulate --material)")
      .def("__repr__", [](const io::SceneFile& f) {
        return "<elastolearn.Scene '" + f.scene.name
            + "': " + std::to_string(f.scene.mesh.num_vertices()) + " vertices, "
            + std::to_string(f.scene.mesh.num_tets()) + " tets, " + std::to_string(f.scene.frames)
            + " frames>";
      });

  py::class_<Material>(m, "Material",
      "A material (elastolearn-material/1, docs/file_formats.md): the nominal model (a "
      "scene-format material object), an optional learned correction and its training "
      "provenance.")
      .def_static(
          "load",
          [](const std::filesystem::path& path) {
            return make_material(io::read_material_file(path), path.string());
          },
          py::arg("path"), "Read and validate a material file.")
      .def_static(
          "from_json",
          [](const py::handle& json, const std::string& name) {
            return make_material(io::parse_material_file(to_json(json), name), name);
          },
          py::arg("json"), py::arg("name") = "material",
          "A material from a material file's JSON as a dict: {\"format\": "
          "\"elastolearn-material/1\", \"material\": {scene-format material}, \"correction\": "
          "None or {...}}; messages name `name`.")
      .def(
          "to_json", [](const Material& m) { return to_python(io::material_file_to_json(m.file)); },
          "The material file's JSON as a dict.")
      .def(
          "write",
          [](const Material& m, const std::filesystem::path& path) {
            io::write_material_file(path, m.file);
          },
          py::arg("path"), "Write the material file (atomically).")
      .def_readonly("source", &Material::source)
      .def_property_readonly(
          "nominal", [](const Material& m) { return to_python(m.file.material); },
          "the nominal model as a scene-format material object")
      .def_property_readonly(
          "training", [](const Material& m) { return to_python(m.file.training); },
          "free-form training provenance (learn's options, the recipe's choice, history)")
      .def_property_readonly(
          "elastic_model", [](const Material& m) { return m.model.elastic->name(); })
      .def_property_readonly(
          "correction",
          [](const Material& m) -> py::object {
            if (!m.file.correction)
              return py::none();
            return py::str(io::describe_correction(*m.file.correction));
          },
          "a description of the correction, or None")
      .def_property_readonly(
          "training_stretches",
          [](const Material& m) -> py::object {
            if (!m.file.training_stretches)
              return py::none();
            return to_python(io::stretch_range_to_json(*m.file.training_stretches));
          },
          "{'min': [s1, s2, s3], 'max': [...]} of the training motion, or None")
      .def_property_readonly(
          "description", [](const Material& m) { return io::describe_material_model(m.model); })
      .def("principal_stress", &principal_stress, py::arg("stretches"),
          py::arg("stretch_rates") = py::none(),
          "Principal first Piola stress P̂(σ) + N(σ, σ̇) [Pa], (m, 3), at stretches (m, 3) "
          "and stretch rates (m, 3) [1/s] (default 0). Rows in any order.")
      .def("energy", &energy, py::arg("stretches"),
          "Energy density Ψ(σ) [J/m³] of the nominal elastic model, (m,), at stretches (m, 3).")
      .def("__repr__", [](const Material& m) {
        return "<elastolearn.Material " + io::describe_material_model(m.model) + ">";
      });
}

} // namespace elastolearn::python
