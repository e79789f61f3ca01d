#include <elastolearn/io/scene_output.hpp>
#include <elastolearn/io/trajectory_file.hpp>

namespace elastolearn::io {

std::map<std::string, std::string> simulation_metadata(
    const sim::Scene& scene, int every, const sim::SimulationReport& report) {
  return { { "scene", scene.name }, { "material", scene.material.elastic->name() },
    { "dt", std::to_string(scene.dt * std::max(1, every)) },
    { "status", report.completed ? "completed" : "stopped: " + report.message } };
}

TrajectoryData simulate_trajectory(const sim::Scene& scene, int every,
    const ProgressCallback& progress, sim::SimulationReport& report) {
  TrajectoryData data;
  data.rest_positions = scene.mesh.rest_positions();
  data.tets = scene.mesh.tets();
  data.faces = scene.mesh.surface_faces();
  every = std::max(1, every);
  auto sink = [&](int frame, double time, const VecX& x, const VecX& v) {
    if (frame % every != 0)
      return;
    data.positions.emplace_back(unflatten(x));
    data.velocities.emplace_back(unflatten(v));
    data.time.push_back(time);
  };
  report = sim::run_simulation(scene, sink, progress);
  data.metadata = simulation_metadata(scene, every, report);
  return data;
}

sim::SimulationReport simulate_to_files(const sim::Scene& scene, const SceneOutputOptions& options,
    const ProgressCallback& progress, std::filesystem::path* pvd,
    learn::StretchCoverage* coverage) {
  TrajectoryWriter writer(options.trajectory, scene.mesh.rest_positions(), scene.mesh.tets(),
      Edges(), scene.mesh.surface_faces());
  TrajectoryData series; // in memory only when a ParaView series is requested
  if (options.vtu_directory) {
    series.rest_positions = scene.mesh.rest_positions();
    series.tets = scene.mesh.tets();
  }
  const int every = std::max(1, options.every);
  auto sink = [&](int frame, double time, const VecX& x, const VecX& v) {
    if (coverage)
      coverage->add_frame(x);
    if (frame % every != 0)
      return;
    const Positions positions = unflatten(x);
    const Positions velocities = unflatten(v);
    writer.append(time, positions, velocities);
    if (options.vtu_directory) {
      series.positions.push_back(positions);
      series.velocities.push_back(velocities);
      series.time.push_back(time);
    }
  };
  sim::SimulationReport report = sim::run_simulation(scene, sink, progress);
  const std::map<std::string, std::string> metadata = simulation_metadata(scene, every, report);
  if (writer.frames() > 0)
    writer.finish(metadata);
  if (options.vtu_directory && !series.positions.empty()) {
    series.metadata = metadata;
    const auto p = write_vtu_series(*options.vtu_directory, scene.name, series);
    if (pvd)
      *pvd = p;
  }
  return report;
}

} // namespace elastolearn::io
