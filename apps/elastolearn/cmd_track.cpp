// elastolearn track scene.json --clouds clouds.h5 -o tracked.h5 [--sigma S] [--weight λ] [-q]
// Physics-based tracking (paper 000 §5.3, Fig. 3a): the scene is simulated with its nominal
// material while every step is pulled toward the frame's point cloud; the result is a trajectory
// of the whole mesh (docs/tracking.md).
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/observe/cloud_observation.hpp>
#include <elastolearn/observe/cloud_tracking.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {

struct TrackCommandOptions {
  std::string scene;
  std::string clouds;
  std::string output;
  std::string observations;
  elastolearn::observe::TrackingOptions tracking;
  bool quiet = false;
  bool sigma_given = false;
};

void run_track(TrackCommandOptions opts) {
  using namespace elastolearn;
  const auto file = io::read_scene_file(opts.scene);
  std::vector<CommandInput> inputs = file.inputs;
  inputs.push_back({ opts.clouds, "point clouds (--clouds)" });
  std::vector<CommandOutput> outputs { { opts.output, "tracked trajectory (-o)" } };
  if (!opts.observations.empty())
    outputs.push_back({ opts.observations, "observations (--observations)" });
  check_command_paths(inputs, outputs);
  const capture::PointCloudSequence clouds = io::read_clouds_h5(opts.clouds);
  const double noise = io::read_clouds_noise_sigma(opts.clouds);
  const std::string sigma_source = opts.sigma_given ? "--sigma"
      : noise > 0                                   ? "the clouds' noise_sigma"
                                                    : "half the clouds' point spacing";
  if (!opts.sigma_given)
    opts.tracking.sigma = observe::default_tracking_sigma(clouds, noise, opts.clouds);
  opts.tracking.validate();

  const sim::Scene& scene = file.scene;
  std::printf(
      "scene %s: %d vertices, %d tets, %s; %d frames of %lld points (%lld .. %lld per "
      "frame)\n",
      scene.name.c_str(), scene.mesh.num_vertices(), scene.mesh.num_tets(),
      scene.material.elastic->name().c_str(), clouds.num_frames(),
      static_cast<long long>(clouds.num_points()),
      [&] {
        long long m = clouds.num_points();
        for (int t = 0; t < clouds.num_frames(); ++t)
          m = std::min<long long>(m, clouds.frame_size(t));
        return m;
      }(),
      [&] {
        long long m = 0;
        for (int t = 0; t < clouds.num_frames(); ++t)
          m = std::max<long long>(m, clouds.frame_size(t));
        return m;
      }());

  std::vector<Positions> tracked; // for --observations
  io::TrajectoryWriter writer(opts.output, scene.mesh.rest_positions(), scene.mesh.tets(), Edges(),
      scene.mesh.surface_faces());
  const auto report = observe::track_clouds(
      scene, clouds, opts.clouds, opts.tracking,
      [&](int, double time, const VecX& x, const VecX& v) {
        writer.append(time, Eigen::Map<const Positions>(x.data(), x.size() / 3, 3),
            Eigen::Map<const Positions>(v.data(), v.size() / 3, 3));
        if (!opts.observations.empty())
          tracked.emplace_back(unflatten(x));
      },
      opts.quiet ? ProgressCallback {} : terminal_progress("track"));

  std::printf("σ = %g m (%s%s), λ = %g: pull %.3g N/m³ of observed surface; %d surface samples, "
              "%d coarse-to-fine levels\n",
      report.sigma, sigma_source.c_str(),
      report.sigma > opts.tracking.sigma ? ", raised to the sample floor" : "",
      opts.tracking.weight, report.stiffness_per_area, report.samples, report.levels);
  std::string rms_list, inlier_list;
  double worst = 0, sum = 0, sum_inliers = 0;
  int worst_frame = 0, seen = 0;
  long em = 0, newton = 0;
  long long points = 0, outliers = 0;
  for (std::size_t t = 0; t < report.frames.size(); ++t) {
    const auto& f = report.frames[t];
    rms_list += (t ? " " : "") + to_text_exact(f.rms);
    inlier_list += (t ? " " : "") + to_text_exact(f.rms_inliers);
    em += f.em_iterations;
    newton += f.newton_iterations;
    if (f.points == 0)
      continue;
    ++seen;
    sum += f.rms * f.rms;
    sum_inliers += f.rms_inliers * f.rms_inliers;
    points += f.points;
    outliers += f.outliers;
    if (f.rms_inliers > worst) {
      worst = f.rms_inliers;
      worst_frame = static_cast<int>(t);
    }
  }
  const int n = static_cast<int>(report.frames.size());
  std::printf("%s: %d frames in %.2f s (%.1f ms/frame, %.2f solves and %.1f Newton iterations "
              "per frame)\n",
      report.completed ? "completed" : "stopped", n, report.seconds,
      1e3 * report.seconds / std::max(1, n), double(em) / std::max(1, n),
      double(newton) / std::max(1, n));
  std::printf("cloud → surface RMS distance over the %d frames with points: %.3g m within %g σ "
              "of the surface (worst frame %d: %.3g m), %.3g m over all points; %.2f %% of the "
              "points farther\n",
      seen, seen ? std::sqrt(sum_inliers / seen) : 0.0, observe::k_inlier_distance, worst_frame,
      worst, seen ? std::sqrt(sum / seen) : 0.0,
      points ? 100.0 * double(outliers) / double(points) : 0.0);
  for (const std::string& note : report.notes)
    std::printf("note: %s\n", note.c_str());
  if (writer.frames() > 0) {
    writer.finish({ { "scene", scene.name }, { "material", scene.material.elastic->name() },
        { "dt", to_text_exact(scene.dt) }, { "clouds", opts.clouds },
        { "status", report.completed ? "completed" : "stopped: " + report.message },
        { "tracking_sigma", to_text_exact(report.sigma) },
        { "tracking_weight", to_text_exact(opts.tracking.weight) }, { "tracking_rms", rms_list } });
    std::printf("trajectory: %s\n", opts.output.c_str());
  }
  if (report.completed && !opts.observations.empty()) {
    observe::CloudObservationOptions observing;
    observing.sigma = report.sigma;
    const observe::Observation observed
        = observe::observe_clouds(scene.mesh.surface_vertices(), tracked, clouds, observing);
    io::write_observation_h5(opts.observations, observed);
    std::printf("observations: %s (%s of %d surface vertices' frames seen)\n",
        opts.observations.c_str(), to_text(observed.num_valid()).c_str(),
        observed.num_observed() * observed.num_frames());
  }
  if (!report.completed) {
    std::fprintf(stderr, "elastolearn: error: %s\n", report.message.c_str());
    throw CLI::RuntimeError(1);
  }
}

void add_track_command(CLI::App& root) {
  auto opts = std::make_shared<TrackCommandOptions>();
  auto* cmd = root.add_subcommand("track",
      "Physics-based tracking: simulate a scene pulled toward point clouds (HDF5) and write the "
      "tracked trajectory (HDF5)");
  cmd->add_option("scene", opts->scene,
         "scene file (elastolearn-scene/1 JSON): mesh, nominal "
         "material, time step; its frames + 1 = the clouds' frames")
      ->required();
  cmd->add_option("--clouds", opts->clouds, "point-cloud HDF5 (scan, import-clouds)")->required();
  cmd->add_option("-o,--output", opts->output, "tracked trajectory HDF5 to write")->required();
  cmd->add_option("--observations", opts->observations,
      "also write the surface observations learn derives from the clouds around the tracked "
      "surface (observation HDF5; docs/tracking.md)");
  auto* sigma = cmd->add_option("--sigma", opts->tracking.sigma,
      "correspondence σ [m] (default: the clouds' noise_sigma, else half their point spacing)");
  cmd->add_option("--weight", opts->tracking.weight,
      "λ, the pull's stiffness relative to the material's (default 1; docs/tracking.md)");
  cmd->add_option("--tangential-weight", opts->tracking.tangential_weight,
      "τ in [0, 1]: weight of the tangential part of a point's distance in the pull (1: point "
      "to point, 0: point to plane; docs/tracking.md)");
  cmd->add_option("--em-iterations", opts->tracking.em_iterations,
      "most correspondence updates per frame and σ level (default 5)");
  cmd->add_flag("-q,--quiet", opts->quiet, "no progress line");
  cmd->callback([opts, sigma] {
    opts->sigma_given = sigma->count() > 0;
    run_track(*opts);
  });
}

} // namespace

ELASTOLEARN_COMMAND(33, add_track_command)
