// `elastolearn tetrahedralize surface.off --max-tets 3000 [--scale 0.001] -o out.node`: closed
// surface → tet mesh (TetGen run as an external program), printing counts, quality and output
// paths.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/surface_mesh.hpp>
#include <elastolearn/mesh/tetgen_io.hpp>
#include <elastolearn/mesh/tetrahedralize.hpp>

#include <cmath>
#include <cstdio>
#include <memory>

namespace elastolearn::app {

namespace {

struct TetrahedralizeArgs {
  std::string input;
  std::string output;
  double scale = 1; ///< applied to the surface before meshing (e.g. 0.001: millimetres → metres)
  mesh::TetrahedralizeOptions options;
};

void run_tetrahedralize(const TetrahedralizeArgs& args) {
  const std::filesystem::path out(args.output);
  if (out.has_extension() && out.extension() != ".node" && out.extension() != ".ele")
    throw InputError(args.output, "output must be a TetGen .node/.ele path (or their common stem)");
  if (!(args.scale > 0 && std::isfinite(args.scale)))
    throw InputError(
        "--scale", "must be a positive number (a negative scale would mirror the mesh)");
  const auto [node, ele] = mesh::tetgen_files(out);
  check_command_paths({ { args.input, "surface" } },
      { { node, "tet mesh output (.node)" }, { ele, "tet mesh output (.ele, beside the .node)" } });
  mesh::SurfaceMesh surface = mesh::read_surface_mesh(args.input);
  surface.vertices *= args.scale;
  char scaled[48] = "";
  if (args.scale != 1)
    std::snprintf(scaled, sizeof scaled, " (scaled by %g)", args.scale);
  std::printf("surface   %s: %d vertices, %d faces, enclosed volume %.6g%s\n", args.input.c_str(),
      static_cast<int>(surface.vertices.rows()), static_cast<int>(surface.faces.rows()),
      mesh::enclosed_volume(surface), scaled);
  mesh::TetrahedralizeReport report;
  const mesh::TetMesh tets = mesh::tetrahedralize(surface, args.options, &report, args.input);
  if (report.holes_filled > 0)
    std::printf("filled %d holes of the surface\n", report.holes_filled);
  if (report.simplified)
    std::printf(
        "simplified the surface to %d faces to reach the tet budget\n", report.surface_faces);
  for (const auto& run : report.runs)
    std::printf("  tetgen %-28s faces %6d -> %7d tets  (%.2f s)\n", run.switches.c_str(),
        run.surface_faces, run.num_tets, run.seconds);
  const mesh::MeshQuality q = tets.quality();
  std::printf("tet mesh  %d tets, %d vertices, %d surface faces, volume %.6g\n", tets.num_tets(),
      tets.num_vertices(), static_cast<int>(tets.surface_faces().rows()), tets.total_volume());
  std::printf(
      "quality   dihedral [%.2f, %.2f] deg, max radius ratio %.3g, tet volume [%.3g, %.3g]\n",
      q.min_dihedral_deg, q.max_dihedral_deg, q.max_radius_ratio, q.min_volume, q.max_volume);
  const auto stem = mesh::tetgen_stem(out);
  mesh::write_tetgen(out, tets);
  std::printf("wrote     %s.node, %s.ele (%.2f s)\n", stem.string().c_str(), stem.string().c_str(),
      report.seconds);
}

} // namespace

void add_tetrahedralize_command(CLI::App& root) {
  auto args = std::make_shared<TetrahedralizeArgs>();
  CLI::App* cmd = root.add_subcommand(
      "tetrahedralize", "Tetrahedralize a closed surface (.obj/.off/.ply/.stl) with TetGen");
  cmd->add_option("surface", args->input, "closed triangle surface")->required();
  cmd->add_option("-o,--output", args->output, "output TetGen mesh (.node; .ele written beside it)")
      ->required();
  cmd->add_option("--max-tets", args->options.max_tets,
      "target tet count (not exceeded by more than 10%; 0 = no target)");
  cmd->add_option("--scale", args->scale,
      "scale the surface by this positive factor before meshing (e.g. 0.001: mm to m); "
      "--max-volume is in the scaled units");
  cmd->add_option("--max-volume", args->options.max_volume, "maximum tet volume (0 = none)");
  cmd->add_option(
         "--quality", args->options.min_radius_edge_ratio, "maximum radius-edge ratio (TetGen -q)")
      ->capture_default_str();
  cmd->add_option("--min-dihedral", args->options.min_dihedral_deg,
      "minimum dihedral angle in degrees (TetGen -q ratio/angle; 0 = default)");
  cmd->add_option("--tetgen", args->options.tetgen_executable,
      "TetGen program (default: $ELASTOLEARN_TETGEN or the one found at build time)");
  cmd->add_flag("--fill-holes", args->options.fill_holes,
      "close holes of an open surface (fan around each hole's centroid) before meshing");
  cmd->add_flag("-v,--verbose", args->options.verbose, "show TetGen's output");
  cmd->callback([args] { run_tetrahedralize(*args); });
}

} // namespace elastolearn::app

using elastolearn::app::add_tetrahedralize_command;
ELASTOLEARN_COMMAND(20, add_tetrahedralize_command)
