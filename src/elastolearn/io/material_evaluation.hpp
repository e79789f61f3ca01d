#pragma once
/// \file Paper 000 Table 1's err_L: simulate a test scene with its own (nominal) material and with
/// a learned material, and compare both with the true trajectory over all vertices. What
/// `elastolearn evaluate` and the Python `evaluate` run; the JSON is evaluate's `--json` report.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// The true trajectory `truth` (read from `source`) as flat frames (3n each, frame 0 = initial
/// state), after checking that it belongs to `scene`: the same vertex count and rest shape (within
/// 10⁻⁹ of the size), scene.frames + 1 frames spaced scene.dt. Throws InputError naming `source`
/// and the dataset.
std::vector<VecX> truth_frames(
    const TrajectoryData& truth, const std::string& source, const sim::Scene& scene);

/// truth_frames of the trajectory file at `path`.
std::vector<VecX> read_truth_trajectory(const std::filesystem::path& path, const sim::Scene& scene);

/// What a test motion is compared with: the true trajectory of every vertex, or observations of
/// some of the scene mesh's vertices — e.g. a coarse mesh's vertices carried by a fine mesh's
/// motion (`observe --onto`, paper 000 §7.3), when the truth was simulated on another mesh.
struct EvaluationTruth {
  std::vector<VecX> frames; ///< flat 3n per frame (frame 0 = initial state), or empty
  std::optional<observe::Observation> observed; ///< set instead of `frames`
  int num_frames() const;
};

/// The truth file at `path` for `scene`: an observation file (io::is_observation_h5), validated
/// against the scene (vertex ids < n, scene.frames + 1 frames, dt), or else a trajectory file
/// (read_truth_trajectory). Throws InputError naming `path` and the dataset.
EvaluationTruth read_evaluation_truth(const std::filesystem::path& path, const sim::Scene& scene);

/// One simulated model and its error against the truth.
struct ModelRun {
  std::string label; ///< "nominal" or "learned"
  std::string description; ///< the material, for users
  std::vector<VecX> frames; ///< flat 3n, frame 0 = initial state
  sim::SimulationReport report;
  learn::ErrorSummary error; ///< [m]
  learn::ErrorSummary percent; ///< [% of the rest bounding-box diagonal]
};

/// Simulate `scene` into `run` (its frames kept in memory; written to `output` as a trajectory
/// file if not empty). `run.label` and `run.description` are the caller's.
void simulate_model(const sim::Scene& scene, const ProgressCallback& progress,
    const std::filesystem::path& output, ModelRun& run);

/// One run's errors and status, as in evaluate's `--json` report.
nlohmann::json model_run_to_json(const ModelRun& run);

struct MaterialEvaluation;

struct EvaluationOptions {
  /// Write the learned material's trajectory here (HDF5) if not empty.
  std::filesystem::path learned_trajectory;
  /// The progress callback of the run labelled `label` (none: no progress).
  std::function<ProgressCallback(const std::string& label)> progress;
  /// Called after the set-up, before the first simulation (labels and descriptions are set).
  std::function<void(const MaterialEvaluation&)> started;
};

/// The comparison of the nominal and the learned material on one test motion.
struct MaterialEvaluation {
  double size = 0; ///< rest bounding-box diagonal [m]
  int truth_frames = 0;
  /// Vertices the errors are measured at: the truth's observed ones, or −1 for every vertex.
  int truth_vertices = -1;
  ModelRun nominal; ///< the test scene's material
  ModelRun learned; ///< the learned material (the scene's mesh, boundary conditions, time)
  /// Where the learned run's motion leaves the correction's training stretches (material files
  /// that record them, with a correction).
  std::optional<learn::StretchCoverage> coverage;
  /// nominal / learned of the max and mean errors; nothing when the learned error is zero.
  std::optional<double> max_ratio() const;
  std::optional<double> mean_ratio() const;
  bool completed() const { return nominal.report.completed && learned.report.completed; }
};

/// Simulate `scene` with its material and with `material` (read from `material_source`, which
/// names it in messages and descriptions), and compare both with `truth` (from
/// read_truth_trajectory). A simulation that stops early is a result (ModelRun::report), its
/// errors cover the frames before. Throws InputError for an invalid material.
MaterialEvaluation evaluate_material(const sim::Scene& scene, const MaterialFile& material,
    const std::string& material_source, const std::vector<VecX>& truth,
    const EvaluationOptions& options = {});
/// The same against either kind of truth: with observations, err_L and the other statistics are
/// over the observed (frame, vertex) entries that were seen (learn::observation_error) — the
/// same definition, over fewer vertices.
MaterialEvaluation evaluate_material(const sim::Scene& scene, const MaterialFile& material,
    const std::string& material_source, const EvaluationTruth& truth,
    const EvaluationOptions& options = {});

/// The report ("format": "elastolearn-evaluation/1"; docs/file_formats.md): the file names as
/// given, the scene's sizes and both runs' errors.
nlohmann::json evaluation_to_json(const MaterialEvaluation& evaluation, const sim::Scene& scene,
    const std::string& scene_path, const std::string& material_path, const std::string& truth_path);

} // namespace elastolearn::io
