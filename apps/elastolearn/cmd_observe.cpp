// elastolearn observe traj.h5 (--visible-fraction F | --vertices FILE | --all) [--onto SCENE]
//                    [--noise SIGMA] [--dropout P [--dropout-burst L]] [--seed S] -o obs.h5
// Observations for learning (paper 000 §7): some surface vertices of a trajectory, spread over
// the surface, with optional Gaussian noise and lost markers; with --onto, the vertices of
// another mesh of the object carried by the trajectory's motion (§7.3, coarsening). Format:
// docs/observations.md.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/io/trajectory_observation.hpp>
#include <elastolearn/observe/observation.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>

namespace {

struct ObserveOptions {
  std::string trajectory;
  std::string output;
  std::string vertices;
  std::string onto;
  bool all = false;
  double fraction = 0;
  double noise = 0;
  double dropout = 0;
  double dropout_burst = 5;
  std::uint64_t seed = 1;
};

void run_observe(const ObserveOptions& opts) {
  using namespace elastolearn;
  std::vector<CommandInput> inputs = { { opts.trajectory, "trajectory" } };
  if (!opts.vertices.empty())
    inputs.push_back({ opts.vertices, "vertex list (--vertices)" });
  std::optional<io::SceneFile> onto;
  if (!opts.onto.empty()) {
    onto = io::read_scene_file(opts.onto);
    for (const CommandInput& input : onto->inputs)
      inputs.push_back({ input.path, input.role + " (--onto)" });
  }
  check_command_paths(inputs, { { opts.output, "observation output (-o)" } });
  io::ObservationRequest request;
  request.all_vertices = opts.all;
  if (onto) {
    request.onto = &onto->scene.mesh;
    request.onto_source = opts.onto;
  }
  if (!opts.vertices.empty()) {
    request.vertices = io::read_vertex_id_list(opts.vertices);
    request.vertices_source = opts.vertices;
  }
  request.visible_fraction = opts.fraction;
  request.noise = opts.noise;
  request.seed = opts.seed;
  request.dropout = opts.dropout;
  request.dropout_burst = opts.dropout_burst;
  const io::TrajectoryObservation observed
      = io::observe_trajectory(io::read_trajectory_h5(opts.trajectory), opts.trajectory, request);
  const observe::Observation& obs = observed.observation;
  io::write_observation_h5(opts.output, obs, observed.metadata);

  const std::string mesh = onto ? " of " + opts.onto + "'s mesh" : "";
  if (opts.all)
    std::printf("observed all %d vertices%s (%d on the surface) over %d frames, dt = %g s",
        obs.num_observed(), mesh.c_str(), observed.surface_vertices, obs.num_frames(), obs.dt);
  else
    std::printf("observed %d vertices%s (%d surface vertices, %.1f %%) over %d frames, dt = %g s",
        obs.num_observed(), mesh.c_str(), observed.surface_vertices,
        100.0 * obs.num_observed() / std::max(1, observed.surface_vertices), obs.num_frames(),
        obs.dt);
  if (opts.noise > 0)
    std::printf(
        ", noise sigma = %g m (%.3g %% of the size)", opts.noise, 100 * opts.noise / observed.size);
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
  auto* all = cmd->add_flag("--all", opts->all, "observe every vertex, interior ones too");
  fraction->excludes(vertices)->excludes(all);
  vertices->excludes(fraction)->excludes(all);
  all->excludes(fraction)->excludes(vertices);
  cmd->add_option("--onto", opts->onto,
      "observe the vertices of this scene's mesh instead (another mesh of the object, e.g. a "
      "coarse one): each follows the trajectory's tet that contains it at rest");
  cmd->add_option("--noise", opts->noise, "Gaussian noise standard deviation [m] (default 0)");
  cmd->add_option("--dropout", opts->dropout,
      "lost markers: fraction [0, 1) of vertex-frames lost in occlusion bursts (written as NaN, "
      "/observed/valid 0; default 0)");
  cmd->add_option("--dropout-burst", opts->dropout_burst,
      "mean length of a burst of loss [frames] (geometric; default 5)");
  cmd->add_option(
      "--seed", opts->seed, "seed for the vertex choice, the noise and the dropout (default 1)");
  cmd->callback([opts, fraction, vertices, all] {
    if (fraction->count() == 0 && vertices->count() == 0 && all->count() == 0) {
      throw elastolearn::InputError(
          "observe", "give --visible-fraction F, --vertices FILE or --all to choose the vertices");
    }
    run_observe(*opts);
  });
}

} // namespace

ELASTOLEARN_COMMAND(30, add_observe_command)
