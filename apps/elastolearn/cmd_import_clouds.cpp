// elastolearn import-clouds DIR --dt DT [--start-time T0] -o clouds.h5
// Point clouds as scanning tools export them (one PLY or XYZ file per frame, in a folder, ordered
// by name naturally) into one point-cloud HDF5 file. Formats: docs/file_formats.md.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/cloud_import.hpp>

#include <algorithm>
#include <cmath>
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
  if (!(opts.dt > 0) || !std::isfinite(opts.dt))
    throw InputError("--dt", "the time between frames must be positive, got " + to_text(opts.dt));
  if (!std::isfinite(opts.start_time))
    throw InputError("--start-time", "must be finite");
  // Frame by frame from the folder to the file: a long capture never has to fit in memory.
  io::CloudWriter writer(opts.output, opts.dt, opts.start_time);
  long empty = 0;
  long long fewest = -1, most = 0;
  bool normals = false, confidence = false;
  io::read_point_cloud_folder(
      opts.folder, [&](const std::filesystem::path&, const capture::CloudFrame& frame) {
        writer.append(frame);
        const long long n = frame.points.rows();
        empty += n == 0;
        fewest = fewest < 0 ? n : std::min(fewest, n);
        most = std::max(most, n);
        normals |= frame.normals.rows() > 0;
        confidence |= frame.confidence.size() > 0;
      });
  writer.finish({ { "source", opts.folder }, { "first_file", files.front().filename().string() },
      { "last_file", files.back().filename().string() } });
  std::printf("imported %ld frames (%s .. %s), dt = %g s: %lld points, %lld .. %lld per frame",
      writer.frames(), files.front().filename().c_str(), files.back().filename().c_str(), opts.dt,
      writer.points(), fewest, most);
  if (empty > 0)
    std::printf(", %ld empty frame%s", empty, empty == 1 ? "" : "s");
  std::printf("%s%s\npoint clouds: %s\n", normals ? ", with normals" : "",
      confidence ? ", with confidence" : "", opts.output.c_str());
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

ELASTOLEARN_COMMAND(32, add_import_clouds_command)
