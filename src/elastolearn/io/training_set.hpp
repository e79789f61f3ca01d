#pragma once
/// \file Training-set JSON files ("format": "elastolearn-training/1", docs/observations.md,
/// "Training sets"): the recorded motions of one object that `learn` learns one correction from,
///   {"format": "elastolearn-training/1",
///    "motions": [{"scene": "droop.json", "observations": "droop.h5"},
///                {"scene": "swing.json", "clouds": "swing_clouds.h5"}, ...]}
/// A motion has observations (vertex trajectories) or point clouds (learned from by tracking:
/// learn/cloud_motion.hpp). Scene, observation and cloud paths are relative to the training-set
/// file's folder (or absolute). Every motion's scene has the same nominal material (a correction is
/// a material property); meshes, boundary conditions, dt and lengths may differ.
#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/learn/motion.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

namespace elastolearn::io {

/// The files of one motion: paths relative to the current folder (or absolute). Exactly one of
/// `observations` and `clouds` is set.
struct TrainingSetEntry {
  std::filesystem::path scene;
  std::filesystem::path observations;
  std::filesystem::path clouds = {}; ///< a point-cloud file (elastolearn-clouds)
};

/// One motion as read: its resolved paths and its scene file (whose `scene` is the motion's
/// scene; the observations or clouds are in TrainingSet::motions).
struct TrainingSetFiles {
  TrainingSetEntry paths; ///< resolved against the training-set file's folder
  SceneFile scene_file;
};

/// A validated training set, ready to learn from.
struct TrainingSet {
  std::filesystem::path path; ///< the training-set file (empty for a single scene + observations)
  std::vector<TrainingSetFiles> files; ///< per motion
  /// Per motion: name (the observation or cloud file's resolved path), scene (nominal material,
  /// lumped mass, no correction) and observations (validated against the scene), or for clouds
  /// the capture (frames and dt checked against the scene; learn_material observes it).
  std::vector<learn::Motion> motions;
  /// The nominal material every motion shares, as a scene-format "material" object
  /// (SceneFile::nominal_material): what the learned material file starts from.
  nlohmann::json nominal_material;
  /// Every file read: the training-set file, each scene's inputs (SceneFile::inputs) and each
  /// observation or cloud file, for check_command_paths.
  std::vector<CommandInput> inputs;
};

/// Read a training-set file, every scene and observation file it names, and validate them.
/// Throws InputError naming the file and field ("set.json: motions[1].observations") for: a
/// wrong or missing "format"; "motions" missing, not an array or empty; a motion that is not an
/// object, lacks "scene" or has not exactly one of "observations" and "clouds" (non-empty
/// strings) or has other keys; unknown keys at the root; a scene, observation or cloud file that
/// cannot be read (its reader's error); observations or clouds that do not fit their scene
/// (vertex ids, frames + 1 frames, dt); a scene whose material is heterogeneous ("regions") or
/// already carries a correction, or whose mass is not lumped; a scene whose nominal material
/// differs from the first motion's.
TrainingSet read_training_set(const std::filesystem::path& path);

/// A training set of one motion from a scene file and its observation or cloud file (`paths`,
/// exactly one of the two set), with the same checks as read_training_set (errors name the
/// file). `path` stays empty.
TrainingSet read_training_motion(const TrainingSetEntry& paths);

/// What `learn` learns from: the training-set file `scene_or_set` (then `observations` and
/// `clouds` must be empty) or a scene file and its observation or cloud file (exactly one);
/// `observations_name` and `clouds_name` name those arguments in messages ("--observations",
/// "--clouds"). Also checks that the shared nominal material has parameters to fit (E, ν,
/// constant Rayleigh damping), naming the first scene file's field. Throws InputError as
/// read_training_set / read_training_motion, or naming the argument for a missing or
/// superfluous data file.
TrainingSet read_learning_data(const std::filesystem::path& scene_or_set,
    const std::filesystem::path& observations, const std::string& observations_name,
    const std::filesystem::path& clouds = {}, const std::string& clouds_name = "--clouds");

/// True if `path` is a JSON file whose root "format" names a training set (any version); false
/// for anything else, including files that cannot be read, so that a caller can tell a training
/// set from a scene file and report the matching reader's errors.
bool is_training_set_file(const std::filesystem::path& path);

/// The training-set document of `motions` (paths relative to the current folder or absolute) as
/// written to `path`: each path relative to path's folder (lexically, after making both
/// absolute), so that the set reads back from any working folder and moves with its files.
nlohmann::json training_set_to_json(
    const std::filesystem::path& path, const std::vector<TrainingSetEntry>& motions);

/// Write training_set_to_json atomically (temporary file + rename). Does not read the scenes or
/// observations. Throws InputError if `motions` is empty, a path is empty, or the file cannot be
/// written.
void write_training_set(
    const std::filesystem::path& path, const std::vector<TrainingSetEntry>& motions);

} // namespace elastolearn::io
