// elastolearn observe traj.h5 (--visible-fraction F | --vertices FILE) [--noise SIGMA]
//                    [--dropout P [--dropout-burst L]] [--seed S] -o obs.h5
// Observations for learning (paper 000 §7): some surface vertices of a trajectory, spread over
// the surface, with optional Gaussian noise and lost markers. Format: docs/observations.md.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/observe/marker_dropout.hpp>
#include <elastolearn/observe/visible_vertices.hpp>

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <map>

namespace {

struct ObserveOptions {
  std::string trajectory;
  std::string output;
  std::string vertices;
  double fraction = 0;
  double noise = 0;
  double dropout = 0;
  double dropout_burst = 5;
  std::uint64_t seed = 1;
};

/// Shortest text that reads back as `v` (the file's metadata are strings).
std::string exact(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

void run_observe(const ObserveOptions& opts) {
  using namespace elastolearn;
  std::vector<CommandInput> inputs = { { opts.trajectory, "trajectory" } };
  if (!opts.vertices.empty())
    inputs.push_back({ opts.vertices, "vertex list (--vertices)" });
  check_command_paths(inputs, { { opts.output, "observation output (-o)" } });
  const io::TrajectoryData traj = io::read_trajectory_h5(opts.trajectory);
  if (traj.tets.rows() == 0) {
    throw InputError(opts.trajectory + ": /tets",
        "missing: observing needs the tet mesh to know the surface (simulate a scene to get one)");
  }
  const mesh::TetMesh mesh(traj.rest_positions, traj.tets, opts.trajectory);
  const double dt = observe::uniform_time_step(traj.time, opts.trajectory + ": /time");

  std::vector<int> ids;
  if (!opts.vertices.empty()) {
    ids = io::read_vertex_id_list(opts.vertices);
    for (int id : ids) {
      if (id >= mesh.num_vertices()) {
        throw InputError(opts.vertices,
            "vertex id " + std::to_string(id) + " is out of range [0, "
                + std::to_string(mesh.num_vertices()) + ") of the mesh in " + opts.trajectory);
      }
    }
  } else {
    ids = observe::select_visible_vertices(mesh, opts.fraction, opts.seed);
  }
  observe::Observation obs = observe::observe_vertices(
      traj.positions, dt, ids, opts.noise, opts.seed, traj.time.front());
  // The dropout draws from its own stream (seed + 1), so adding it leaves the noise unchanged.
  observe::drop_markers(obs, opts.dropout, opts.dropout_burst, opts.seed + 1);
  const std::string selection = opts.vertices.empty()
      ? "visible fraction " + exact(opts.fraction) + " (farthest-point sampling)"
      : "vertex list " + opts.vertices;
  std::map<std::string, std::string> metadata { { "source", opts.trajectory },
    { "selection", selection }, { "noise_sigma", exact(opts.noise) },
    { "seed", std::to_string(opts.seed) } };
  if (opts.dropout > 0) {
    metadata["dropout"] = exact(opts.dropout);
    metadata["dropout_burst"] = exact(opts.dropout_burst);
  }
  io::write_observation_h5(opts.output, obs, metadata);

  const int surface = static_cast<int>(mesh.surface_vertices().size());
  std::printf("observed %d vertices (%d surface vertices, %.1f %%) over %d frames, dt = %g s",
      obs.num_observed(), surface, 100.0 * obs.num_observed() / std::max(1, surface),
      obs.num_frames(), dt);
  if (opts.noise > 0)
    std::printf(", noise sigma = %g m (%.3g %% of the size)", opts.noise,
        100 * opts.noise / mesh.bounding_box_diagonal());
  if (opts.dropout > 0)
    std::printf(", %s in bursts of mean %g frames", observe::describe_lost_entries(obs).c_str(),
        opts.dropout_burst);
  std::printf("\nobservation: %s\n", opts.output.c_str());
}

void add_observe_command(CLI::App& root) {
  auto opts = std::make_shared<ObserveOptions>();
  auto* cmd = root.add_subcommand("observe",
      "Observe some surface vertices of a trajectory (HDF5) for learning, with optional noise");
  cmd->add_option("trajectory", opts->trajectory, "trajectory HDF5 with /tets (from simulate)")
      ->required();
  cmd->add_option("-o,--output", opts->output, "observation HDF5 to write")->required();
  auto* fraction = cmd->add_option("--visible-fraction", opts->fraction,
      "fraction (0, 1] of the surface vertices, spread by farthest-point sampling");
  auto* vertices = cmd->add_option("--vertices", opts->vertices,
      "text file of vertex ids to observe (white space or commas, # comments)");
  fraction->excludes(vertices);
  vertices->excludes(fraction);
  cmd->add_option("--noise", opts->noise, "Gaussian noise standard deviation [m] (default 0)");
  cmd->add_option("--dropout", opts->dropout,
      "lost markers: fraction [0, 1) of vertex-frames lost in occlusion bursts (written as NaN, "
      "/observed/valid 0; default 0)");
  cmd->add_option("--dropout-burst", opts->dropout_burst,
      "mean length of a burst of loss [frames] (geometric; default 5)");
  cmd->add_option(
      "--seed", opts->seed, "seed for the vertex choice, the noise and the dropout (default 1)");
  cmd->callback([opts, fraction, vertices] {
    if (fraction->count() == 0 && vertices->count() == 0) {
      throw elastolearn::InputError(
          "observe", "give --visible-fraction F or --vertices FILE to choose the vertices");
    }
    run_observe(*opts);
  });
}

} // namespace

ELASTOLEARN_COMMAND(30, add_observe_command)
