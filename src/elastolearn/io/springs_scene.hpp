#pragma once
/// \file Springs scene JSON ("format": "elastolearn-springs-scene/1") and learned-spring JSON
/// ("format": "elastolearn-learned-spring/1"); formats documented in docs/springs.md. Every error
/// names the file and the field.
#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/springs/learned_simulator.hpp>
#include <elastolearn/springs/simulation_run.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace elastolearn::io {

/// A rope or cloth scene: the system, the spring to learn (or a learned spring file), the
/// simulation mode and its loads and outputs.
struct SpringsScene {
  std::string name;
  std::string system_type; ///< "rope" | "cloth"
  springs::SpringSystem system;
  springs::TrainingOptions training; ///< reference law + data generation
  springs::LearnOptions learning; ///< features + ridge
  std::optional<std::filesystem::path> learned_spring; ///< use this file instead of learning
  bool reference = false; ///< mode "reference": hand-written springs
  springs::LearnedSimulatorOptions simulation; ///< mode, dt, solver
  int steps = 100;
  springs::Loads loads;
  std::optional<std::filesystem::path> trajectory; ///< output HDF5 (relative to the scene)
  std::optional<std::filesystem::path> vtu_directory; ///< output VTU/PVD folder
  int every = 1; ///< record every k-th step
  /// The files the scene was read from: the scene file (when read from a file) and its learned
  /// spring file, so that a command can refuse to overwrite them (check_command_paths).
  std::vector<CommandInput> inputs;
};

/// Read and validate a springs scene. Throws InputError naming the file and field.
SpringsScene read_springs_scene(const std::filesystem::path& path);
/// Parse from JSON in memory; `file` is used in messages, `base_dir` resolves relative paths.
SpringsScene parse_springs_scene(
    const nlohmann::json& json, const std::string& file, const std::filesystem::path& base_dir);

/// The learned spring of a scene: read from `learned_spring` or learned from `training`.
springs::LearnedSpring scene_learned_spring(const SpringsScene& scene);
/// The scene's stepper (reference or learned in its mode).
std::unique_ptr<springs::SpringStepper> make_scene_stepper(const SpringsScene& scene);

/// Learned spring as JSON: features, coefficients ((p+1)×2 rows [Δe, Δv], intercept first),
/// dt, mass, fit report, and (optional) the law it was trained on.
nlohmann::json learned_spring_to_json(
    const springs::LearnedSpring& spring, const springs::SpringLaw* trained_on = nullptr);
/// Parse a learned spring. Throws InputError naming the file and field.
springs::LearnedSpring learned_spring_from_json(
    const nlohmann::json& json, const std::string& file);
/// Write atomically. Throws InputError.
void write_learned_spring(const std::filesystem::path& path, const springs::LearnedSpring& spring,
    const springs::SpringLaw* trained_on = nullptr);
/// Read and validate. Throws InputError.
springs::LearnedSpring read_learned_spring(const std::filesystem::path& path);

/// A recorded springs run as trajectory data (edges = springs, faces for cloth) for HDF5/VTU.
TrajectoryData springs_trajectory(
    const springs::SpringSystem& system, const springs::SimulationRecord& record);

} // namespace elastolearn::io
