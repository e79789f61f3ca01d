#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_evaluation.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/observe/observation.hpp>

#include <cmath>
#include <map>

namespace elastolearn::io {

std::vector<VecX> read_truth_trajectory(
    const std::filesystem::path& path, const sim::Scene& scene) {
  return truth_frames(read_trajectory_h5(path), path.string(), scene);
}

int EvaluationTruth::num_frames() const {
  return observed ? observed->num_frames() : static_cast<int>(frames.size());
}

EvaluationTruth read_evaluation_truth(const std::filesystem::path& path, const sim::Scene& scene) {
  EvaluationTruth truth;
  if (!is_observation_h5(path)) {
    truth.frames = read_truth_trajectory(path, scene);
    return truth;
  }
  truth.observed = read_observation_h5(path);
  truth.observed->validate(scene.mesh.num_vertices(), scene.frames + 1, scene.dt, path.string());
  return truth;
}

std::vector<VecX> truth_frames(
    const TrajectoryData& truth, const std::string& path, const sim::Scene& scene) {
  const int n = scene.mesh.num_vertices();
  if (truth.rest_positions.rows() != n) {
    throw InputError(path + ": /rest_positions",
        "has " + std::to_string(truth.rest_positions.rows()) + " vertices but the scene's mesh has "
            + std::to_string(n) + " (a trajectory of a different mesh?)");
  }
  const double tolerance = 1e-9 * scene.mesh.bounding_box_diagonal();
  const double offset
      = (truth.rest_positions - scene.mesh.rest_positions()).rowwise().norm().maxCoeff();
  if (!(offset <= tolerance)) {
    throw InputError(path + ": /rest_positions",
        "differ from the scene's mesh by up to " + std::to_string(offset)
            + " m (a trajectory of a different mesh?)");
  }
  const int expected = scene.frames + 1;
  if (int(truth.positions.size()) != expected) {
    throw InputError(path + ": /positions",
        "has " + std::to_string(truth.positions.size()) + " frames but the scene simulates "
            + std::to_string(expected) + " (" + std::to_string(scene.frames)
            + " steps + the initial state)");
  }
  const double dt = observe::uniform_time_step(truth.time, path + ": /time");
  if (std::abs(dt - scene.dt) > 1e-6 * scene.dt) {
    throw InputError(path + ": /time",
        "frames are " + std::to_string(dt) + " s apart but the scene's time step is "
            + std::to_string(scene.dt) + " s");
  }
  std::vector<VecX> frames;
  frames.reserve(truth.positions.size());
  for (const Positions& p : truth.positions)
    frames.emplace_back(flatten(p));
  return frames;
}

void simulate_model(const sim::Scene& scene, const ProgressCallback& progress,
    const std::filesystem::path& output, ModelRun& run) {
  std::optional<TrajectoryWriter> writer;
  if (!output.empty())
    writer.emplace(output, scene.mesh.rest_positions(), scene.mesh.tets(), Edges(),
        scene.mesh.surface_faces());
  auto sink = [&](int, double time, const VecX& x, const VecX& v) {
    run.frames.push_back(x);
    if (writer)
      writer->append(time, unflatten(x), unflatten(v));
  };
  run.report = sim::run_simulation(scene, sink, progress);
  if (writer && writer->frames() > 0) {
    const std::map<std::string, std::string> metadata = { { "scene", scene.name },
      { "material", run.description }, { "dt", std::to_string(scene.dt) },
      { "status", run.report.completed ? "completed" : "stopped: " + run.report.message } };
    writer->finish(metadata);
  }
}

nlohmann::json model_run_to_json(const ModelRun& run) {
  const auto& e = run.error;
  const auto& p = run.percent;
  return { { "material", run.description }, { "err_L_percent", p.max }, { "mean_percent", p.mean },
    { "rms_percent", p.rms }, { "max_error", e.max }, { "mean_error", e.mean },
    { "rms_error", e.rms }, { "worst_frame", e.worst_frame }, { "worst_vertex", e.worst_vertex },
    { "frames_compared", run.frames.size() }, { "completed", run.report.completed },
    { "message", run.report.message }, { "seconds", run.report.seconds } };
}

namespace {

/// nominal / learned, or nothing when the learned error is zero.
std::optional<double> ratio(double nominal, double learned) {
  if (!(learned > 0))
    return std::nullopt;
  return nominal / learned;
}

nlohmann::json optional_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

} // namespace

std::optional<double> MaterialEvaluation::max_ratio() const {
  return ratio(nominal.error.max, learned.error.max);
}

std::optional<double> MaterialEvaluation::mean_ratio() const {
  return ratio(nominal.error.mean, learned.error.mean);
}

MaterialEvaluation evaluate_material(const sim::Scene& scene, const MaterialFile& material,
    const std::string& material_source, const std::vector<VecX>& truth,
    const EvaluationOptions& options) {
  EvaluationTruth all;
  all.frames = truth;
  return evaluate_material(scene, material, material_source, all, options);
}

MaterialEvaluation evaluate_material(const sim::Scene& scene, const MaterialFile& material,
    const std::string& material_source, const EvaluationTruth& truth,
    const EvaluationOptions& options) {
  sim::Scene learned_scene = scene;
  learned_scene.material = material_model(material, material_source);
  MaterialEvaluation e;
  e.size = scene.mesh.bounding_box_diagonal();
  e.truth_frames = truth.num_frames();
  e.truth_vertices = truth.observed ? truth.observed->num_observed() : -1;
  e.nominal.label = "nominal";
  e.nominal.description = describe_material_model(scene.material) + " (the scene's)";
  e.learned.label = "learned";
  e.learned.description
      = describe_material_model(learned_scene.material) + " (" + material_source + ")";
  if (options.started)
    options.started(e);
  const auto progress = [&](const std::string& label) {
    return options.progress ? options.progress(label) : ProgressCallback {};
  };
  simulate_model(scene, progress(e.nominal.label), {}, e.nominal);
  simulate_model(learned_scene, progress(e.learned.label), options.learned_trajectory, e.learned);
  for (ModelRun* run : { &e.nominal, &e.learned }) {
    run->error = truth.observed ? learn::observation_error(run->frames, *truth.observed)
                                : learn::position_error(run->frames, truth.frames);
    run->percent = learn::as_percent_of(run->error, e.size);
  }
  if (material.training_stretches && material.correction) {
    e.coverage.emplace(scene.mesh, material.training_stretches);
    for (const VecX& x : e.learned.frames)
      e.coverage->add_frame(x);
  }
  return e;
}

nlohmann::json evaluation_to_json(const MaterialEvaluation& e, const sim::Scene& scene,
    const std::string& scene_path, const std::string& material_path,
    const std::string& truth_path) {
  nlohmann::json report = {
    { "format", "elastolearn-evaluation/1" }, { "scene", scene_path },
    { "material", material_path }, { "truth", truth_path },
    { "vertices", scene.mesh.num_vertices() }, { "tets", scene.mesh.num_tets() },
    { "frames", e.truth_frames }, { "dt", scene.dt }, { "size", e.size },
    { "truth_vertices",
        e.truth_vertices < 0 ? nlohmann::json("all") : nlohmann::json(e.truth_vertices) },
    { "nominal", model_run_to_json(e.nominal) }, { "learned", model_run_to_json(e.learned) },
    { "improvement",
        { { "err_L", optional_json(e.max_ratio()) }, { "mean", optional_json(e.mean_ratio()) } } }
  };
  if (e.coverage) {
    report["stretches"] = { { "visited", stretch_range_to_json(e.coverage->visited()) },
      { "trained", stretch_range_to_json(*e.coverage->trained()) },
      { "fraction_outside", e.coverage->fraction_outside() } };
  }
  return report;
}

} // namespace elastolearn::io
