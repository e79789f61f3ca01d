// elastolearn import-clouds DIR --dt DT [--start-time T0] -o clouds.h5
// Point clouds as scanning tools export them (one PLY or XYZ file per frame, in a folder, ordered
// by name naturally) into one point-cloud HDF5 file. Formats: docs/file_formats.md.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/cloud_import.hpp>

#include <cstdio>

namespace {

struct ImportOptions {
  std::string folder;
  std::string output;
  double dt = 0;
  double start_time = 0;
};

void run_import(const ImportOptions& opts) {
  using namespace elastolearn;
  const auto files = io::list_point_cloud_files(opts.folder);
  std::vector<CommandInput> inputs;
  for (const auto& file : files)
    inputs.push_back({ file, "point-cloud frame" });
  check_command_paths(inputs, { { opts.output, "point-cloud output (-o)" } });
  const capture::PointCloudSequence clouds
      = io::import_point_clouds(opts.folder, opts.dt, opts.start_time);
  io::write_clouds_h5(opts.output, clouds,
      { { "source", opts.folder }, { "first_file", files.front().filename().string() },
          { "last_file", files.back().filename().string() } });
  int empty = 0;
  Eigen::Index fewest = clouds.num_points(), most = 0;
  for (int t = 0; t < clouds.num_frames(); ++t) {
    empty += clouds.frame_size(t) == 0;
    fewest = std::min(fewest, clouds.frame_size(t));
    most = std::max(most, clouds.frame_size(t));
  }
  std::printf("imported %d frames (%s .. %s), dt = %g s: %ld points, %ld .. %ld per frame",
      clouds.num_frames(), files.front().filename().c_str(), files.back().filename().c_str(),
      clouds.dt, long(clouds.num_points()), long(fewest), long(most));
  if (empty > 0)
    std::printf(", %d empty frame%s", empty, empty == 1 ? "" : "s");
  std::printf("%s%s\npoint clouds: %s\n", clouds.has_normals() ? ", with normals" : "",
      clouds.has_confidence() ? ", with confidence" : "", opts.output.c_str());
}

void add_import_clouds_command(CLI::App& root) {
  auto opts = std::make_shared<ImportOptions>();
  auto* cmd = root.add_subcommand("import-clouds",
      "Gather a folder of per-frame point clouds (.ply, .xyz) into one HDF5 point-cloud file");
  cmd->add_option("folder", opts->folder,
         "folder with one .ply or .xyz file per frame, in natural name order (frame_2 before "
         "frame_10)")
      ->required();
  cmd->add_option("--dt", opts->dt, "time between frames [s]")->required();
  cmd->add_option("--start-time", opts->start_time, "time of the first frame [s] (default 0)");
  cmd->add_option("-o,--output", opts->output, "point-cloud HDF5 to write")->required();
  cmd->callback([opts] { run_import(*opts); });
}

} // namespace

ELASTOLEARN_COMMAND(31, add_import_clouds_command)
