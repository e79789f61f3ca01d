#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/nominal_parameters.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/training_set.hpp>

#include <string>

namespace elastolearn::io {

namespace {

constexpr const char* k_format_kind = "elastolearn-training";
constexpr int k_format_version = 1;

/// A motion's point-cloud capture, checked against its scene (frames + 1 frames of its dt).
std::shared_ptr<const learn::CloudCapture> read_capture(
    const std::filesystem::path& path, const sim::Scene& scene, const std::string& where) {
  auto capture = std::make_shared<learn::CloudCapture>();
  capture->clouds = read_clouds_h5(path);
  capture->sigma = read_clouds_noise_sigma(path);
  capture->source = path.string();
  const int frames = capture->clouds.num_frames();
  if (frames != scene.frames + 1)
    throw InputError(where,
        "has " + to_text(frames) + " frames, the scene " + to_text(scene.frames + 1)
            + " (time.frames + 1)");
  if (std::abs(capture->clouds.dt - scene.dt) > 1e-9 * scene.dt)
    throw InputError(where,
        "dt " + to_text_exact(capture->clouds.dt) + " s differs from the scene's "
            + to_text_exact(scene.dt) + " s");
  return capture;
}

/// Adds one motion (its files already resolved) to `set`, checking it for learning. `scene_where`
/// and `data_where` name the motion's fields in messages (data: observations or clouds).
void add_motion(TrainingSet& set, const TrainingSetEntry& paths, const std::string& scene_where,
    const std::string& data_where) {
  SceneFile scene_file = read_scene_file(paths.scene);
  const sim::Scene& scene = scene_file.scene;
  if (scene.material.correction)
    throw InputError(scene_where,
        "material: the scene's material already carries a correction; learn from a nominal one");
  if (scene.material.stiffness_scale)
    throw InputError(scene_where,
        "material.regions: learning needs one homogeneous nominal material (a correction is one "
        "material's); learn on a homogeneous mesh, e.g. a coarse one (examples/09_coarsening)");
  if (scene.mass != fem::MassType::Lumped)
    throw InputError(scene_where,
        "mass: learning needs \"lumped\" mass (the paper's); learn with lumped mass and simulate "
        "the learned material with either (docs/learning_loop.md, \"Lumped mass only\")");
  if (set.motions.empty()) {
    set.nominal_material = scene_file.nominal_material;
  } else if (scene_file.nominal_material != set.nominal_material) {
    throw InputError(scene_where,
        "material: the nominal material differs from the first motion's ("
            + set.files.front().paths.scene.string()
            + "); a training set holds motions of one material");
  }
  set.inputs.insert(set.inputs.end(), scene_file.inputs.begin(), scene_file.inputs.end());
  if (!paths.clouds.empty()) {
    set.inputs.push_back({ paths.clouds, "point clouds" });
    set.motions.push_back(
        { paths.clouds.string(), scene, {}, read_capture(paths.clouds, scene, data_where) });
  } else {
    observe::Observation observed = read_observation_h5(paths.observations);
    observed.validate(scene.mesh.num_vertices(), scene.frames + 1, scene.dt, data_where);
    set.inputs.push_back({ paths.observations, "observations" });
    set.motions.push_back({ paths.observations.string(), scene, std::move(observed) });
  }
  set.files.push_back({ paths, std::move(scene_file) });
}

/// `p` resolved against `folder` (absolute paths stay).
std::filesystem::path resolved(const std::filesystem::path& folder, const std::string& p) {
  const std::filesystem::path path(p);
  return path.is_absolute() ? path : folder / path;
}

/// `p` (relative to the current folder or absolute) written relative to `folder` when possible.
std::string relative_to(const std::filesystem::path& folder, const std::filesystem::path& p) {
  const std::filesystem::path absolute = std::filesystem::absolute(p).lexically_normal();
  const std::filesystem::path relative = absolute.lexically_relative(folder);
  return (relative.empty() ? absolute : relative).generic_string();
}

} // namespace

TrainingSet read_training_set(const std::filesystem::path& path) {
  const nlohmann::json json = read_json_file(path);
  const std::string file = path.string();
  const JsonObject root(json, file);
  check_format(root, k_format_kind, k_format_version);
  root.reject_unknown_keys({ "format", "motions" });
  const std::vector<JsonObject> entries = root.objects("motions");
  if (entries.empty())
    root.fail("motions",
        "needs at least one motion (an object with \"scene\" and \"observations\" or "
        "\"clouds\")");
  TrainingSet set;
  set.path = path;
  set.inputs.push_back({ path, "training set" });
  const std::filesystem::path folder = path.parent_path();
  for (const JsonObject& entry : entries) {
    entry.reject_unknown_keys({ "scene", "observations", "clouds" });
    const bool clouds = entry.has("clouds");
    if (clouds && entry.has("observations"))
      entry.fail("clouds", "a motion has observations or clouds, not both");
    const char* data = clouds ? "clouds" : "observations";
    for (const char* key : { "scene", data })
      if (entry.string(key).empty())
        entry.fail(key, "expected a path, got an empty string");
    TrainingSetEntry paths;
    paths.scene = resolved(folder, entry.string("scene"));
    (clouds ? paths.clouds : paths.observations) = resolved(folder, entry.string(data));
    const auto& data_path = clouds ? paths.clouds : paths.observations;
    add_motion(set, paths, file + ": " + entry.field("scene") + " (" + paths.scene.string() + ")",
        file + ": " + entry.field(data) + " (" + data_path.string() + ")");
  }
  return set;
}

TrainingSet read_training_motion(const TrainingSetEntry& paths) {
  TrainingSet set;
  add_motion(set, paths, paths.scene.string(),
      (paths.clouds.empty() ? paths.observations : paths.clouds).string());
  return set;
}

TrainingSet read_learning_data(const std::filesystem::path& scene_or_set,
    const std::filesystem::path& observations, const std::string& observations_name,
    const std::filesystem::path& clouds, const std::string& clouds_name) {
  const bool training_set = is_training_set_file(scene_or_set);
  if (!training_set && observations.empty() && clouds.empty())
    throw InputError(observations_name,
        "(or " + clouds_name
            + ") is required with a scene file (or give a training-set file instead of the "
              "scene: docs/observations.md, \"Training sets\")");
  if (!observations.empty() && !clouds.empty())
    throw InputError(
        clouds_name, "not with " + observations_name + ": learn from one or the other");
  if (training_set && !(observations.empty() && clouds.empty()))
    throw InputError(observations.empty() ? clouds_name : observations_name,
        "not with a training set, which names its observation or cloud files ("
            + scene_or_set.string() + ")");
  TrainingSet set = training_set ? read_training_set(scene_or_set)
                                 : read_training_motion({ scene_or_set, observations, clouds });
  // The nominal must have parameters to fit: said here with the scene file's field.
  material::ElasticModelType nominal_type {};
  nominal_parameters_from_json(
      JsonObject(set.nominal_material, set.files.front().paths.scene.string(), "material"),
      nominal_type);
  return set;
}

bool is_training_set_file(const std::filesystem::path& path) {
  try {
    const nlohmann::json json = read_json_file(path);
    const auto format = json.is_object() ? json.find("format") : json.end();
    return format != json.end() && format->is_string()
        && format->get<std::string>().rfind(std::string(k_format_kind) + "/", 0) == 0;
  } catch (const InputError&) {
    return false;
  }
}

nlohmann::json training_set_to_json(
    const std::filesystem::path& path, const std::vector<TrainingSetEntry>& motions) {
  const std::filesystem::path folder
      = std::filesystem::absolute(path).lexically_normal().parent_path();
  nlohmann::json entries = nlohmann::json::array();
  for (const TrainingSetEntry& motion : motions) {
    nlohmann::json entry = { { "scene", relative_to(folder, motion.scene) } };
    if (motion.clouds.empty())
      entry["observations"] = relative_to(folder, motion.observations);
    else
      entry["clouds"] = relative_to(folder, motion.clouds);
    entries.push_back(std::move(entry));
  }
  return { { "format", std::string(k_format_kind) + "/" + std::to_string(k_format_version) },
    { "motions", entries } };
}

void write_training_set(
    const std::filesystem::path& path, const std::vector<TrainingSetEntry>& motions) {
  if (motions.empty())
    throw InputError(path.string(), "motions: a training set needs at least one motion");
  for (size_t i = 0; i < motions.size(); ++i)
    if (motions[i].scene.empty() || motions[i].observations.empty() == motions[i].clouds.empty())
      throw InputError(path.string(),
          "motions[" + std::to_string(i)
              + "]: needs a scene path and exactly one of an observation and a cloud path");
  write_json_file(path, training_set_to_json(path, motions));
}

} // namespace elastolearn::io
