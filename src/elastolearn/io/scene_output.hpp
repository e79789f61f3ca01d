#pragma once
/// \file Run a scene and write its trajectory (HDF5, streamed frame by frame) and optionally a
/// ParaView series (VTU per frame + PVD). A diverged run keeps the frames before the failure
/// (file attribute status = "diverged: ...").
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <filesystem>
#include <optional>

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

} // namespace elastolearn::io
