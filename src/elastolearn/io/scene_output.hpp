#pragma once
/// \file Run a scene and write its trajectory (HDF5, streamed frame by frame) and optionally a
/// ParaView series (VTU per frame + PVD). A diverged run keeps the frames before the failure
/// (file attribute status = "diverged: ...").
#include <elastolearn/core/progress.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <filesystem>
#include <map>
#include <optional>
#include <string>

namespace elastolearn::io {

struct SceneOutputOptions {
  std::filesystem::path trajectory; ///< HDF5 output
  std::optional<std::filesystem::path> vtu_directory; ///< ParaView output folder
  int every = 1; ///< record every k-th frame
};

/// Simulate `scene` and write the outputs. Returns the simulation report; the .pvd path (if any)
/// is stored in `pvd`. If `coverage` is given, every simulated frame (recorded or not) is added
/// to it.
sim::SimulationReport simulate_to_files(const sim::Scene& scene, const SceneOutputOptions& options,
    const ProgressCallback& progress, std::filesystem::path* pvd = nullptr,
    learn::StretchCoverage* coverage = nullptr);

/// Simulate `scene` into memory: every `every`-th state (the initial one included) with its
/// velocities, and the file metadata simulate_to_files writes (scene, material, dt, status).
/// A diverged run keeps the frames before the failure (`report.completed` false).
TrajectoryData simulate_trajectory(const sim::Scene& scene, int every,
    const ProgressCallback& progress, sim::SimulationReport& report);

/// The metadata of a simulated trajectory file: scene name, elastic model, recorded dt and
/// status ("completed" or "stopped: <why>").
std::map<std::string, std::string> simulation_metadata(
    const sim::Scene& scene, int every, const sim::SimulationReport& report);

} // namespace elastolearn::io
