#include <elastolearn/core/error.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/material_regions.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/placement.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/read_tet_mesh.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>

#include <algorithm>

namespace elastolearn::io {

namespace {

int parse_axis(const JsonObject& o, const std::string& key) {
  const std::string a = o.choice(key, { "x", "y", "z" });
  return a[0] - 'x';
}

/// The optional placement keys of `mesh` (scale, rotate_deg, translate).
mesh::Placement parse_placement(const JsonObject& o) {
  mesh::Placement p;
  if (o.has("scale")) {
    p.scale = o.number("scale");
    if (!(p.scale > 0))
      o.fail("scale",
          "must be positive (a negative scale would mirror the mesh and invert its tets), got "
              + describe_json(o.json().at("scale")));
  }
  p.rotate_deg = o.vec3("rotate_deg", Vec3::Zero());
  p.translate = o.vec3("translate", Vec3::Zero());
  return p;
}

/// The mesh before placement; a mesh file's paths join `inputs`.
mesh::TetMesh unplaced_mesh(
    const JsonObject& o, const std::filesystem::path& base_dir, std::vector<CommandInput>& inputs) {
  const std::vector<std::string> placement = { "scale", "rotate_deg", "translate" };
  auto known = [&](std::vector<std::string> keys) {
    keys.insert(keys.end(), placement.begin(), placement.end());
    return keys;
  };
  if (o.has("file")) {
    o.reject_unknown_keys(known({ "file" }));
    std::filesystem::path p = o.string("file");
    if (p.is_relative())
      p = base_dir / p;
    for (const auto& file : mesh::tet_mesh_files(p))
      inputs.push_back({ file, "mesh of the scene " + o.file() });
    return mesh::read_tet_mesh(p);
  }
  const std::string type = o.choice("type", { "box", "sphere" });
  if (type == "box") {
    o.reject_unknown_keys(known({ "type", "size", "cells" }));
    const Vec3 size = o.vec3("size");
    if (!(size.minCoeff() > 0))
      o.fail("size", "all sizes must be positive");
    const auto cells = o.integers("cells");
    if (cells.size() != 3 || *std::min_element(cells.begin(), cells.end()) < 1)
      o.fail("cells", "expected three positive integers");
    if (6.0 * cells[0] * double(cells[1]) * double(cells[2]) > double(mesh::kMaxGeneratedTets))
      o.fail("cells",
          "6 x " + std::to_string(cells[0]) + " x " + std::to_string(cells[1]) + " x "
              + std::to_string(cells[2]) + " tets is more than a generated mesh may have ("
              + std::to_string(mesh::kMaxGeneratedTets) + ")");
    return mesh::make_box_bar(size, { cells[0], cells[1], cells[2] });
  }
  o.reject_unknown_keys(known({ "type", "radius", "tets" }));
  const int tets = o.integer("tets");
  if (tets < 8)
    o.fail("tets", "must be at least 8");
  if (tets > mesh::kMaxGeneratedTets)
    o.fail("tets",
        "must be at most " + std::to_string(mesh::kMaxGeneratedTets) + " (a generated mesh)");
  return mesh::make_sphere(o.positive("radius"), tets);
}

/// The mesh (file or procedural), scaled, rotated and translated as the scene asks.
mesh::TetMesh parse_mesh(
    const JsonObject& o, const std::filesystem::path& base_dir, std::vector<CommandInput>& inputs) {
  const mesh::Placement placement = parse_placement(o);
  return mesh::place(unplaced_mesh(o, base_dir, inputs), placement, o.file() + ": " + o.path());
}

/// The vertices a selection object names (possibly none).
std::vector<int> select_vertices(const JsonObject& o, const mesh::TetMesh& mesh) {
  o.reject_unknown_keys({ "vertices", "box", "plane", "min", "max" });
  const int kinds = o.has("vertices") + o.has("box") + o.has("plane") + o.has("min") + o.has("max");
  if (kinds != 1)
    o.fail("", "a selection needs exactly one of vertices, box, plane, min, max");
  if (o.has("vertices")) {
    auto v = o.integers("vertices");
    for (int i : v)
      if (i < 0 || i >= mesh.num_vertices())
        o.fail("vertices",
            "index " + std::to_string(i) + " out of range [0, "
                + std::to_string(mesh.num_vertices()) + ")");
    return v;
  }
  if (o.has("box")) {
    const JsonObject b = o.object("box");
    b.reject_unknown_keys({ "min", "max" });
    return mesh::vertices_in_box(mesh, Box3(b.vec3("min"), b.vec3("max")));
  }
  const double tol = 1e-9 * std::max(1.0, mesh.bounding_box_diagonal());
  if (o.has("plane")) {
    const JsonObject p = o.object("plane");
    p.reject_unknown_keys({ "axis", "value", "tolerance" });
    return mesh::vertices_near_plane(
        mesh, parse_axis(p, "axis"), p.number("value"), p.number("tolerance", tol));
  }
  if (o.has("min"))
    return mesh::vertices_with_min_coordinate(mesh, parse_axis(o, "min"), tol);
  return mesh::vertices_with_max_coordinate(mesh, parse_axis(o, "max"), tol);
}

std::vector<int> parse_selection_list(
    const JsonObject& o, const std::string& key, const mesh::TetMesh& mesh) {
  std::vector<int> out;
  for (const auto& s : o.objects(key)) {
    auto v = parse_selection(s, mesh);
    out.insert(out.end(), v.begin(), v.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

sim::KeyframeMotion parse_keyframe(const JsonObject& o, const mesh::TetMesh& mesh) {
  o.reject_unknown_keys({ "select", "sinusoid", "piecewise_linear" });
  sim::KeyframeMotion k;
  k.vertices = parse_selection(o.object("select"), mesh);
  if (o.has("sinusoid") == o.has("piecewise_linear"))
    o.fail("sinusoid", "give exactly one of \"sinusoid\" or \"piecewise_linear\"");
  if (o.has("sinusoid")) {
    const JsonObject s = o.object("sinusoid");
    s.reject_unknown_keys({ "amplitude", "frequency", "until" });
    k.kind = sim::KeyframeMotion::Kind::Sinusoid;
    k.amplitude = s.vec3("amplitude");
    k.frequency = s.positive("frequency");
    k.until = s.number("until", std::numeric_limits<double>::infinity());
  } else {
    const JsonObject s = o.object("piecewise_linear");
    s.reject_unknown_keys({ "times", "offsets" });
    k.kind = sim::KeyframeMotion::Kind::PiecewiseLinear;
    k.times = s.numbers("times");
    const auto& offsets = s.json().at("offsets");
    if (!offsets.is_array() || offsets.size() != k.times.size())
      s.fail("offsets", "expected an array of [x, y, z] offsets, one per time");
    for (size_t i = 0; i < offsets.size(); ++i) {
      const auto& e = offsets[i];
      if (!e.is_array() || e.size() != 3 || !e[0].is_number() || !e[1].is_number()
          || !e[2].is_number())
        s.fail("offsets", "entry " + std::to_string(i) + " is not [x, y, z]");
      k.offsets.emplace_back(e[0].get<double>(), e[1].get<double>(), e[2].get<double>());
    }
    for (size_t i = 1; i < k.times.size(); ++i)
      if (!(k.times[i] > k.times[i - 1]))
        s.fail("times", "must be increasing");
  }
  return k;
}

sim::PointLoad parse_load(const JsonObject& o, const mesh::TetMesh& mesh) {
  o.reject_unknown_keys({ "select", "force", "release_time" });
  sim::PointLoad l;
  l.vertices = parse_selection(o.object("select"), mesh);
  l.total_force = o.vec3("force");
  l.release_time = o.number("release_time", std::numeric_limits<double>::infinity());
  return l;
}

/// `{"type": "trajectory", "file": F, "frame": k}`: frame k of trajectory file F (k < 0 counts
/// from the end), which must have been recorded on the scene's mesh.
void parse_recorded_state(const JsonObject& o, const mesh::TetMesh& mesh,
    const std::filesystem::path& base_dir, sim::InitialCondition& ic,
    std::vector<CommandInput>& inputs) {
  o.reject_unknown_keys({ "type", "file", "frame" });
  std::filesystem::path path = o.string("file");
  if (path.is_relative())
    path = base_dir / path;
  inputs.push_back({ path, "initial state of the scene " + o.file() });
  const std::string name = o.string("file");
  const int requested = o.integer("frame");
  // Errors inside the trajectory file name both the scene field and the file's dataset.
  long frames = 0;
  try {
    frames = read_trajectory_frame_count(path);
  } catch (const InputError& e) {
    o.fail("file", e.what());
  }
  if (frames == 0)
    o.fail("frame", name + " has no frames");
  const long index = requested < 0 ? frames + requested : requested;
  if (index < 0 || index >= frames) {
    o.fail("frame",
        std::to_string(requested) + " is out of range: " + name + " has " + std::to_string(frames)
            + " frames (0.." + std::to_string(frames - 1) + ", or -" + std::to_string(frames)
            + "..-1 counting from the end)");
  }
  TrajectoryFrame frame;
  try {
    frame = read_trajectory_frame(path, index);
  } catch (const InputError& e) {
    o.fail("file", e.what());
  }
  const Eigen::Index n = mesh.num_vertices();
  if (frame.positions.rows() != n) {
    o.fail("file",
        name + " has " + std::to_string(frame.positions.rows())
            + " vertices but the scene mesh has " + std::to_string(n));
  }
  // Same count but another mesh (or the same mesh placed differently) would start the motion
  // from a state that does not belong to this rest shape. Files elastolearn writes hold the rest
  // positions exactly; 1e-6 of the mesh size leaves room for single-precision copies.
  const double tolerance = 1e-6 * mesh.bounding_box_diagonal();
  Eigen::Index worst = 0;
  const double distance
      = (frame.rest_positions - mesh.rest_positions()).rowwise().norm().maxCoeff(&worst);
  if (!(distance <= tolerance)) {
    o.fail("file",
        name + " was recorded on another mesh or placement: the rest position of vertex "
            + std::to_string(worst) + " is " + describe_json(distance)
            + " m from the scene mesh's");
  }
  ic.kind = sim::InitialCondition::Kind::Recorded;
  ic.positions = std::move(frame.positions);
  ic.velocities = std::move(frame.velocities);
  ic.time = frame.time;
}

sim::InitialCondition parse_initial(const JsonObject& o, const mesh::TetMesh& mesh,
    const std::filesystem::path& base_dir, std::vector<CommandInput>& inputs) {
  sim::InitialCondition ic;
  const std::string type = o.choice("type", { "rest", "velocity", "static", "trajectory" }, "rest");
  if (type == "trajectory") {
    parse_recorded_state(o, mesh, base_dir, ic, inputs);
  } else if (type == "rest") {
    o.reject_unknown_keys({ "type" });
  } else if (type == "velocity") {
    o.reject_unknown_keys({ "type", "velocity", "angular_velocity", "center" });
    ic.kind = sim::InitialCondition::Kind::Velocity;
    ic.velocity = o.vec3("velocity", Vec3::Zero());
    ic.angular_velocity = o.vec3("angular_velocity", Vec3::Zero());
    ic.center = o.vec3("center", mesh.bounding_box().center());
  } else {
    o.reject_unknown_keys({ "type", "loads", "load_steps" });
    ic.kind = sim::InitialCondition::Kind::StaticLoad;
    for (const auto& l : o.objects("loads"))
      ic.static_loads.push_back(parse_load(l, mesh));
    ic.load_steps = o.integer("load_steps", 5);
    if (ic.load_steps < 1)
      o.fail("load_steps", "must be at least 1");
  }
  return ic;
}

} // namespace

std::vector<int> parse_selection(const JsonObject& o, const mesh::TetMesh& mesh) {
  std::vector<int> selected = select_vertices(o, mesh);
  if (selected.empty())
    o.fail("", "selects no vertex");
  return selected;
}

SceneFile parse_scene(
    const nlohmann::json& json, const std::string& file, const std::filesystem::path& base_dir) {
  const JsonObject root(json, file);
  check_format(root, "elastolearn-scene", 1);
  root.reject_unknown_keys({ "format", "name", "description", "mesh", "material", "mass", "gravity",
      "fixed", "keyframes", "loads", "initial", "time", "solver", "output" });
  SceneFile out;
  sim::Scene& s = out.scene;
  s.name = root.string("name", std::filesystem::path(file).stem().string());
  s.mesh = parse_mesh(root.object("mesh"), base_dir, out.inputs);
  if (const auto material = referenced_material(root, base_dir))
    out.inputs.push_back({ *material, "material of the scene " + file });
  MaterialFile material_file; // inline object or path of a material file
  // "regions" need the mesh: the material itself is read without them (a material file has none).
  const bool has_regions = json.contains("material") && json.at("material").is_object()
      && json.at("material").contains("regions");
  nlohmann::json homogeneous;
  if (has_regions) {
    homogeneous = json;
    homogeneous["material"].erase("regions");
  }
  s.material = scene_material_model(
      has_regions ? JsonObject(homogeneous, file) : root, base_dir, &material_file);
  if (has_regions)
    s.material.stiffness_scale = parse_material_regions(root.object("material"), s.mesh);
  out.material_training_stretches = material_file.training_stretches;
  out.nominal_material = std::move(material_file.material);
  s.mass = root.choice("mass", { "lumped", "consistent" }, "lumped") == "lumped"
      ? fem::MassType::Lumped
      : fem::MassType::Consistent;
  s.gravity = root.vec3("gravity", Vec3::Zero());
  if (root.has("fixed"))
    s.fixed_vertices = parse_selection_list(root, "fixed", s.mesh);
  if (root.has("keyframes"))
    for (const auto& k : root.objects("keyframes"))
      s.keyframes.push_back(parse_keyframe(k, s.mesh));
  if (root.has("loads"))
    for (const auto& l : root.objects("loads"))
      s.loads.push_back(parse_load(l, s.mesh));
  if (root.has("initial"))
    s.initial = parse_initial(root.object("initial"), s.mesh, base_dir, out.inputs);
  const JsonObject time = root.object("time");
  time.reject_unknown_keys({ "dt", "frames" });
  s.dt = time.positive("dt");
  s.frames = time.integer("frames");
  if (s.frames < 1)
    time.fail("frames", "must be at least 1");
  if (root.has("solver")) {
    const JsonObject solver = root.object("solver");
    solver.reject_unknown_keys({ "linear", "newton_tolerance", "max_newton_iterations",
        "reuse_jacobian", "max_step_halvings", "stall_iterations", "extrapolate_velocity" });
    s.linear_solver = sim::linear_solver_type_from_string(
        solver.choice("linear", { "cholmod", "cg", "eigen-ldlt" }, "cholmod"));
    s.newton.relative_tolerance = solver.positive("newton_tolerance", s.newton.relative_tolerance);
    s.newton.max_iterations = solver.integer("max_newton_iterations", s.newton.max_iterations);
    if (!solver.boolean("reuse_jacobian", true))
      s.newton.jacobian_reuse_contraction = 0;
    s.newton.max_step_halvings = solver.integer("max_step_halvings", s.newton.max_step_halvings);
    if (s.newton.max_step_halvings < 0 || s.newton.max_step_halvings > 10)
      solver.fail("max_step_halvings", "must be in [0, 10]");
    s.newton.stall_iterations = solver.integer("stall_iterations", s.newton.stall_iterations);
    if (s.newton.stall_iterations < 0)
      solver.fail("stall_iterations", "must be ≥ 0 (0: off)");
    s.newton.extrapolate_velocity
        = solver.boolean("extrapolate_velocity", s.newton.extrapolate_velocity);
  }
  if (root.has("output")) {
    const JsonObject o = root.object("output");
    o.reject_unknown_keys({ "trajectory", "vtu", "every" });
    if (o.has("trajectory"))
      out.outputs.trajectory = base_dir / o.string("trajectory");
    if (o.has("vtu"))
      out.outputs.vtu_directory = base_dir / o.string("vtu");
    out.outputs.every = o.integer("every", 1);
    if (out.outputs.every < 1)
      o.fail("every", "must be at least 1");
  }
  try {
    s.validate();
  } catch (const InputError& e) {
    throw InputError(file, e.what());
  }
  return out;
}

SceneFile read_scene_file(const std::filesystem::path& path) {
  SceneFile out = parse_scene(read_json_file(path), path.string(), path.parent_path());
  out.path = path;
  out.inputs.insert(out.inputs.begin(), CommandInput { path, "scene" });
  return out;
}

} // namespace elastolearn::io
