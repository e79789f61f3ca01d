#pragma once
/// \file Scene JSON files ("format": "elastolearn-scene/1"); the format is documented in
/// docs/scene_format.md. Every error names the file and the field.
#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/material/stretch_range.hpp>
#include <elastolearn/sim/scene.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace elastolearn::io {

/// Where a scene asks its results to go (paths relative to the scene file's folder).
struct SceneOutputs {
  std::optional<std::filesystem::path> trajectory; ///< HDF5
  std::optional<std::filesystem::path> vtu_directory;
  int every = 1; ///< record every k-th frame
};

struct SceneFile {
  sim::Scene scene;
  SceneOutputs outputs;
  /// The training range of a learned material the scene references (io::MaterialFile).
  std::optional<material::StretchRange> material_training_stretches;
  /// The scene's nominal material as a scene-format "material" object: the inline object or the
  /// "material" of the material file the scene references (what a learned material starts from).
  nlohmann::json nominal_material;
  std::filesystem::path path;
  /// Every file the scene was read from: the scene file itself (when read from a file), its
  /// mesh file(s) (both .node and .ele of a TetGen mesh), its material file and the trajectory
  /// of a recorded initial state, so that a command can refuse to overwrite any of them
  /// (check_command_paths).
  std::vector<CommandInput> inputs;
};

/// Read and validate a scene file. Throws InputError naming the file and field.
SceneFile read_scene_file(const std::filesystem::path& path);

/// Parse a scene from JSON already in memory; `file` is used in messages and `base_dir` to
/// resolve relative paths.
SceneFile parse_scene(
    const nlohmann::json& json, const std::string& file, const std::filesystem::path& base_dir);

/// A vertex selection: {"vertices": [...]} | {"box": {"min": [..], "max": [..]}} |
/// {"plane": {"axis": "x"|"y"|"z", "value": v, "tolerance": t}} | {"min": "x"} | {"max": "y"}
/// (the vertices at the extreme coordinate along an axis, within 1e-9 of the bounding box).
/// Throws InputError naming the selection object (e.g. "scene.json: fixed[0]: selects no
/// vertex") if it selects no vertex: an empty selection is always a mistake in the scene.
std::vector<int> parse_selection(const JsonObject& object, const mesh::TetMesh& mesh);

} // namespace elastolearn::io
