// elastolearn scan traj.h5 --camera cam.json [--noise SIGMA] [--outliers FRACTION] [--seed S]
//                 [--normals] -o clouds.h5
// The virtual depth scanner (paper 000 §7): depth cameras ray-cast the deformed surface of every
// frame; the points they see, with depth noise and optional outliers, become a point-cloud file.
// Formats: docs/file_formats.md ("Depth cameras", "Point clouds").
#include "command.hpp"

#include <elastolearn/capture/virtual_scanner.hpp>
#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/io/camera_file.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/observe/observation.hpp>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdio>

namespace {

struct ScanCommandOptions {
  std::string trajectory;
  std::string cameras;
  std::string output;
  elastolearn::capture::ScanOptions scan;
  bool quiet = false;
};

/// Shortest text that reads back as `v`.
std::string exact(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

void run_scan(const ScanCommandOptions& opts) {
  using namespace elastolearn;
  check_command_paths({ { opts.trajectory, "trajectory" }, { opts.cameras, "camera file" } },
      { { opts.output, "point-cloud output (-o)" } });
  opts.scan.validate();
  const std::vector<capture::DepthCamera> cameras = io::read_camera_file(opts.cameras);
  const io::TrajectoryData traj = io::read_trajectory_h5(opts.trajectory);
  Faces surface;
  if (traj.tets.rows() > 0)
    surface = mesh::TetMesh(traj.rest_positions, traj.tets, opts.trajectory).surface_faces();
  else if (traj.faces.rows() > 0)
    surface = traj.faces;
  else
    throw InputError(
        opts.trajectory, "has neither /tets nor /faces: the scanner needs a surface to ray-cast");
  if (traj.positions.empty())
    throw InputError(opts.trajectory + ": /positions", "no frames to scan");
  const double dt = traj.positions.size() >= 2
      ? observe::uniform_time_step(traj.time, opts.trajectory + ": /time")
      : 1.0; // a static scan: one frame, any spacing (docs/file_formats.md)

  capture::VirtualScanner scanner(
      surface, static_cast<int>(traj.rest_positions.rows()), cameras, opts.scan);
  io::CloudWriter writer(opts.output, dt, traj.time.front());
  long long fewest = -1, most = 0;
  const auto start = Clock::now();
  capture::scan_frames(
      scanner, traj.positions,
      [&](long, const capture::CloudFrame& cloud) {
        writer.append(cloud);
        const long long n = cloud.points.rows();
        fewest = fewest < 0 ? n : std::min(fewest, n);
        most = std::max(most, n);
      },
      opts.quiet ? ProgressCallback {} : terminal_progress("scan"));
  const double seconds = seconds_since(start);
  writer.finish({ { "source", opts.trajectory }, { "cameras", io::cameras_to_json(cameras).dump() },
      { "noise_sigma", exact(opts.scan.noise) }, { "outliers", exact(opts.scan.outlier_fraction) },
      { "seed", std::to_string(opts.scan.seed) },
      { "surface_faces", std::to_string(surface.rows()) } });

  const long T = writer.frames();
  const double rays = double(scanner.num_pixels()) * double(T);
  std::printf("scanned %ld frames with %zu camera%s (%lld rays per frame, %ld surface triangles): "
              "%lld points, %lld .. %lld per frame\n",
      T, cameras.size(), cameras.size() == 1 ? "" : "s", scanner.num_pixels(), long(surface.rows()),
      writer.points(), fewest, most);
  std::printf(
      "time %.3g s: %.3g frames/s, %.3g Mrays/s\n", seconds, T / seconds, rays / seconds * 1e-6);
  std::printf("point clouds: %s\n", opts.output.c_str());
}

void add_scan_command(CLI::App& root) {
  auto opts = std::make_shared<ScanCommandOptions>();
  auto* cmd = root.add_subcommand("scan",
      "Virtual depth scans of a trajectory's surface (HDF5 point clouds), with noise and outliers");
  cmd->add_option("trajectory", opts->trajectory, "trajectory HDF5 with /tets or /faces")
      ->required();
  cmd->add_option("--camera", opts->cameras,
         "camera file (JSON, one or more depth cameras; docs/file_formats.md)")
      ->required();
  cmd->add_option("-o,--output", opts->output, "point-cloud HDF5 to write")->required();
  cmd->add_option("--noise", opts->scan.noise,
      "standard deviation of the depth noise along each ray [m] (default 0)");
  cmd->add_option("--outliers", opts->scan.outlier_fraction,
      "fraction [0, 1] of seen pixels that return a spurious point in the line of sight "
      "(default 0)");
  cmd->add_option("--seed", opts->scan.seed, "seed of the noise and outliers (default 1)");
  cmd->add_flag("--normals", opts->scan.normals,
      "also write the normal of the triangle each point was seen on");
  cmd->add_flag("-q,--quiet", opts->quiet, "no progress line");
  cmd->callback([opts] { run_scan(*opts); });
}

} // namespace

ELASTOLEARN_COMMAND(31, add_scan_command)
