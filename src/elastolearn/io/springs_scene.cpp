#include <elastolearn/io/springs_scene.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/reference_simulator.hpp>

namespace elastolearn::io {

using namespace elastolearn::springs;

namespace {

SpringSystem parse_system(const JsonObject& o, std::string& type) {
  type = o.choice("type", { "rope", "cloth" });
  if (type == "rope") {
    o.reject_unknown_keys({ "type", "nodes", "rest_length", "mass" });
    const int nodes = o.integer("nodes");
    if (nodes < 2)
      o.fail("nodes", "a rope needs at least 2 nodes, got " + std::to_string(nodes));
    if (nodes > kMaxSpringNodes)
      o.fail("nodes",
          "must be at most " + std::to_string(kMaxSpringNodes) + ", got " + std::to_string(nodes));
    return make_rope(nodes, o.positive("rest_length", 1.0), o.positive("mass", 1.0));
  }
  o.reject_unknown_keys({ "type", "columns", "rows", "spacing", "shear", "plane", "pins", "mass" });
  ClothOptions c;
  c.columns = o.integer("columns");
  c.rows = o.integer("rows", c.columns);
  if (c.columns < 2)
    o.fail("columns", "must be >= 2, got " + std::to_string(c.columns));
  if (c.rows < 2)
    o.fail("rows", "must be >= 2, got " + std::to_string(c.rows));
  if (double(c.columns) * double(c.rows) > double(kMaxSpringNodes))
    o.fail("",
        std::to_string(c.columns) + " x " + std::to_string(c.rows) + " nodes is more than "
            + std::to_string(kMaxSpringNodes));
  c.spacing = o.positive("spacing", 1.0);
  c.shear = o.boolean("shear", true);
  c.plane = cloth_plane_from_string(
      o.choice("plane", { "vertical", "horizontal" }, "vertical"), o.field("plane"));
  c.pins = cloth_pins_from_string(
      o.choice("pins", { "top-corners", "top-row", "none" }, "top-corners"), o.field("pins"));
  c.node_mass = o.positive("mass", 1.0);
  return make_cloth(c);
}

SpringLaw parse_law(const JsonObject& o) {
  o.reject_unknown_keys({ "law", "k", "c", "k3", "k_compression" });
  SpringLaw law;
  law.kind = spring_law_kind_from_string(
      o.choice("law", { "linear", "cubic", "bilinear" }, "linear"), o.field("law"));
  law.k = o.positive("k");
  law.c = o.number("c", 0.0);
  if (law.c < 0)
    o.fail("c", "damping must be >= 0, got " + std::to_string(law.c));
  law.k3 = o.number("k3", 0.0);
  if (law.kind == SpringLawKind::cubic && !(law.k3 >= 0))
    o.fail("k3", "must be >= 0");
  law.k_compression = o.number("k_compression", law.kind == SpringLawKind::bilinear ? law.k : 0.0);
  if (law.k_compression < 0)
    o.fail("k_compression", "must be >= 0");
  return law;
}

FeatureMap parse_features(const JsonObject& o, const std::vector<double>& elongations) {
  FeatureMap f;
  f.kind = feature_kind_from_string(
      o.choice("features", { "polynomial", "spline" }, "polynomial"), o.field("features"));
  f.degree = o.integer("degree", 1);
  if (f.kind == FeatureKind::polynomial && (f.degree < 1 || f.degree > 8))
    o.fail("degree", "must be in 1..8, got " + std::to_string(f.degree));
  if (f.kind == FeatureKind::spline) {
    if (o.has("knots")) {
      f.knots = o.numbers("knots");
      try {
        f.validate();
      } catch (const InputError&) {
        o.fail("knots", "expected at least 2 strictly increasing finite elongations");
      }
    } else {
      const int count = o.integer("knot_count", 11);
      if (count < 2)
        o.fail("knot_count", "must be >= 2");
      double lo = 0, hi = 0;
      for (double e : elongations)
        lo = std::min(lo, e), hi = std::max(hi, e);
      f.knots = uniform_knots(lo, hi, count);
    }
  }
  return f;
}

} // namespace

SpringsScene parse_springs_scene(
    const nlohmann::json& json, const std::string& file, const std::filesystem::path& base_dir) {
  const JsonObject root(json, file);
  check_format(root, "elastolearn-springs-scene", 1);
  root.reject_unknown_keys({ "format", "name", "description", "system", "spring", "learning",
      "simulation", "gravity", "loads", "output" });
  SpringsScene scene;
  scene.name = root.string("name", "springs scene");
  scene.system = parse_system(root.object("system"), scene.system_type);
  const int n = scene.system.node_count();

  const JsonObject spring = root.object("spring");
  if (spring.has("model")) {
    spring.reject_unknown_keys({ "model" });
    scene.learned_spring = base_dir / spring.string("model");
    scene.inputs.push_back({ *scene.learned_spring, "learned spring of the scene " + file });
  } else {
    scene.training.law = parse_law(spring);
  }

  if (root.has("learning")) {
    const JsonObject l = root.object("learning");
    l.reject_unknown_keys({ "features", "degree", "knots", "knot_count", "ridge", "sampling",
        "elongations", "steps" });
    if (l.has("elongations")) {
      scene.training.elongations = l.numbers("elongations");
      if (scene.training.elongations.empty())
        l.fail("elongations", "needs at least one value");
    }
    scene.learning.features = parse_features(l, scene.training.elongations);
    scene.learning.ridge = l.number("ridge", 0.0);
    if (scene.learning.ridge < 0)
      l.fail("ridge", "must be >= 0");
    scene.training.sampling = sampling_kind_from_string(
        l.choice("sampling", { "trajectories", "phase-grid" }, "trajectories"),
        l.field("sampling"));
    scene.training.steps = l.integer("steps", scene.training.steps);
    if (scene.training.steps < 2)
      l.fail("steps", "must be >= 2");
  }

  const JsonObject sim = root.object("simulation");
  sim.reject_unknown_keys({ "mode", "dt", "steps", "solver", "cg_tolerance", "cg_max_iterations" });
  const std::string mode
      = sim.choice("mode", { "reference", "paper", "explicit", "implicit" }, "explicit");
  scene.reference = mode == "reference";
  if (!scene.reference)
    scene.simulation.mode = learned_mode_from_string(mode, sim.field("mode"));
  scene.simulation.dt = sim.positive("dt", 0.01);
  scene.training.dt = scene.simulation.dt;
  scene.steps = sim.integer("steps");
  if (scene.steps < 1)
    sim.fail("steps", "must be >= 1, got " + std::to_string(scene.steps));
  scene.simulation.solver = linear_solver_from_string(
      sim.choice("solver", { "auto", "direct", "cg" }, "auto"), sim.field("solver"));
  scene.simulation.cg_tolerance = sim.positive("cg_tolerance", 1e-8);
  if (scene.simulation.cg_tolerance >= 1)
    sim.fail("cg_tolerance", "must be < 1");
  scene.simulation.cg_max_iterations = sim.integer("cg_max_iterations", 2000);
  if (scene.simulation.cg_max_iterations < 1)
    sim.fail("cg_max_iterations", "must be >= 1");

  scene.loads.gravity = root.vec3("gravity", Vec3::Zero());
  scene.loads.forces = Positions::Zero(n, 3);
  if (root.has("loads")) {
    for (const JsonObject& load : root.objects("loads")) {
      load.reject_unknown_keys({ "nodes", "force" });
      const Vec3 force = load.vec3("force");
      for (int a : load.integers("nodes")) {
        if (a < 0 || a >= n)
          load.fail("nodes",
              "node " + std::to_string(a) + " out of range [0, " + std::to_string(n) + ")");
        scene.loads.forces.row(a) += force.transpose();
      }
    }
  }
  if (root.has("output")) {
    const JsonObject out = root.object("output");
    out.reject_unknown_keys({ "trajectory", "vtu", "every" });
    if (out.has("trajectory"))
      scene.trajectory = base_dir / out.string("trajectory");
    if (out.has("vtu"))
      scene.vtu_directory = base_dir / out.string("vtu");
    scene.every = out.integer("every", 1);
    if (scene.every < 1)
      out.fail("every", "must be >= 1, got " + std::to_string(scene.every));
  }
  // Cross-field checks with the library's own validation, reported against the file.
  try {
    if (!scene.learned_spring && !scene.reference)
      scene.training.validate();
  } catch (const InputError& e) {
    throw InputError(file, e.what());
  }
  return scene;
}

SpringsScene read_springs_scene(const std::filesystem::path& path) {
  const nlohmann::json json = read_json_file(path);
  SpringsScene scene = parse_springs_scene(json, path.string(), path.parent_path());
  scene.inputs.insert(scene.inputs.begin(), CommandInput { path, "scene" });
  return scene;
}

springs::LearnedSpring scene_learned_spring(const SpringsScene& scene) {
  if (scene.learned_spring)
    return read_learned_spring(*scene.learned_spring);
  return learn_spring(scene.training, scene.learning);
}

std::unique_ptr<springs::SpringStepper> make_scene_stepper(const SpringsScene& scene) {
  if (scene.reference) {
    if (scene.learned_spring)
      throw InputError("spring.model", "mode 'reference' needs a spring law, not a learned model");
    return std::make_unique<ReferenceSimulator>(
        scene.system, scene.training.law, scene.simulation.dt, scene.loads);
  }
  return make_learned_simulator(
      scene.system, scene_learned_spring(scene), scene.simulation, scene.loads);
}

nlohmann::json learned_spring_to_json(
    const springs::LearnedSpring& spring, const springs::SpringLaw* trained_on) {
  nlohmann::json j;
  j["format"] = "elastolearn-learned-spring/1";
  j["dt"] = spring.dt();
  j["mass"] = spring.mass();
  nlohmann::json f;
  f["kind"] = std::string(to_string(spring.features().kind));
  if (spring.features().kind == FeatureKind::polynomial)
    f["degree"] = spring.features().degree;
  else
    f["knots"] = spring.features().knots;
  j["features"] = f;
  std::vector<std::string> names = { "1" };
  for (const auto& name : spring.features().names())
    names.push_back(name);
  j["feature_names"] = names;
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < spring.coefficients().rows(); ++r)
    rows.push_back({ spring.coefficients()(r, 0), spring.coefficients()(r, 1) });
  j["coefficients"] = rows;
  const FitReport& rep = spring.report();
  j["fit"] = { { "samples", rep.samples }, { "r_squared", rep.r_squared },
    { "rms_residual", rep.rms_residual }, { "max_residual", rep.max_residual } };
  if (trained_on)
    j["trained_on"] = { { "law", std::string(to_string(trained_on->kind)) }, { "k", trained_on->k },
      { "c", trained_on->c }, { "k3", trained_on->k3 },
      { "k_compression", trained_on->k_compression } };
  return j;
}

springs::LearnedSpring learned_spring_from_json(
    const nlohmann::json& json, const std::string& file) {
  const JsonObject root(json, file);
  check_format(root, "elastolearn-learned-spring", 1);
  root.reject_unknown_keys(
      { "format", "dt", "mass", "features", "feature_names", "coefficients", "fit", "trained_on" });
  const JsonObject fo = root.object("features");
  fo.reject_unknown_keys({ "kind", "degree", "knots" });
  FeatureMap features;
  features.kind
      = feature_kind_from_string(fo.choice("kind", { "polynomial", "spline" }), fo.field("kind"));
  if (features.kind == FeatureKind::polynomial)
    features.degree = fo.integer("degree");
  else
    features.knots = fo.numbers("knots");
  try {
    features.validate();
  } catch (const InputError&) {
    if (features.kind == FeatureKind::polynomial)
      fo.fail("degree", "must be in 1..8, got " + std::to_string(features.degree));
    fo.fail("knots", "expected at least 2 strictly increasing finite elongations");
  }
  if (!root.has("coefficients"))
    root.fail("coefficients", "missing required field");
  const auto& rows = json["coefficients"];
  if (!rows.is_array() || static_cast<int>(rows.size()) != features.size() + 1)
    root.fail("coefficients",
        "expected an array of " + std::to_string(features.size() + 1) + " [d_e, d_v] pairs, got "
            + describe_json(rows));
  MatX coefficients(features.size() + 1, 2);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const auto& row = rows[r];
    if (!row.is_array() || row.size() != 2 || !row[0].is_number() || !row[1].is_number())
      root.fail("coefficients[" + std::to_string(r) + "]",
          "expected [d_e, d_v], got " + describe_json(row));
    coefficients(static_cast<Eigen::Index>(r), 0) = row[0].get<double>();
    coefficients(static_cast<Eigen::Index>(r), 1) = row[1].get<double>();
  }
  FitReport report;
  if (root.has("fit")) {
    const JsonObject fit = root.object("fit");
    report.samples = fit.integer("samples", 0);
    if (fit.has("r_squared"))
      report.r_squared = fit.numbers("r_squared");
    if (fit.has("rms_residual"))
      report.rms_residual = fit.numbers("rms_residual");
    if (fit.has("max_residual"))
      report.max_residual = fit.numbers("max_residual");
  }
  return LearnedSpring(
      features, coefficients, root.positive("dt"), root.positive("mass", 1.0), report);
}

void write_learned_spring(const std::filesystem::path& path, const springs::LearnedSpring& spring,
    const springs::SpringLaw* trained_on) {
  write_json_file(path, learned_spring_to_json(spring, trained_on));
}

springs::LearnedSpring read_learned_spring(const std::filesystem::path& path) {
  return learned_spring_from_json(read_json_file(path), path.string());
}

TrajectoryData springs_trajectory(
    const springs::SpringSystem& system, const springs::SimulationRecord& record) {
  TrajectoryData data;
  data.rest_positions = system.rest;
  data.edges = system.springs;
  data.faces = system.faces;
  data.positions = record.positions;
  data.velocities = record.velocities;
  data.time = record.time;
  data.metadata["status"] = record.diverged ? "diverged" : "completed";
  data.metadata["message"] = record.message;
  return data;
}

} // namespace elastolearn::io
