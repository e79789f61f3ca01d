#pragma once
/// \file Tetrahedralizing a closed surface with TetGen, run as an external program.
///
/// TetGen is AGPL-licensed, so elastolearn never links it: it writes the surface to a private
/// temporary directory, runs the `tetgen` program (argument vector, no shell), and reads the
/// `.node/.ele` result back. The program is `ELASTOLEARN_TETGEN_EXECUTABLE` (found by CMake),
/// overridden by the environment variable `ELASTOLEARN_TETGEN` or by the options.
#include <elastolearn/mesh/surface_mesh.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <string>
#include <vector>

namespace elastolearn::mesh {

/// Options for tetrahedralize(). Zero means "not set" for the numeric limits.
struct TetrahedralizeOptions {
  /// Target tet count (0 = none). The max tet volume is adjusted over a few TetGen runs to land
  /// near it without exceeding it by more than 10 %; if the surface is too detailed for the
  /// target even without a volume bound, it is first simplified (quadric edge collapses).
  int max_tets = 0;
  /// Upper bound on every tet volume [m³] (TetGen `-a`; 0 = none). With max_tets, the tighter wins.
  double max_volume = 0;
  /// TetGen quality bound: maximum radius–edge ratio (`-q`), ≥ 1.0 (TetGen needs > ~1.0 to finish).
  double min_radius_edge_ratio = 1.5;
  /// Optional minimum dihedral angle [degrees] for TetGen's `-q ratio/angle` (0 = TetGen default).
  double min_dihedral_deg = 0;
  /// Number of TetGen runs allowed to hit max_tets.
  int max_iterations = 8;
  /// Close holes (boundary loops) of an open surface before meshing (see fill_holes()); without
  /// it an open surface is an error.
  bool fill_holes = false;
  /// Pass TetGen's output through (to stderr) instead of running it quietly.
  bool verbose = false;
  /// TetGen program; empty = $ELASTOLEARN_TETGEN, else the one found at configure time.
  std::string tetgen_executable;

  /// Throws InputError naming the field for a negative count/volume, ratio < 1, angle outside
  /// [0, 70) or iterations < 1.
  void validate() const;
};

/// One TetGen run.
struct TetgenRun {
  std::string switches; ///< e.g. "-pq1.5a0.002zQ"
  double max_volume = 0; ///< the -a bound used (0 = none)
  int surface_faces = 0; ///< faces of the surface given to TetGen
  int num_tets = 0; ///< result (0 if the run failed)
  double seconds = 0; ///< wall time
};

/// What tetrahedralize() did.
struct TetrahedralizeReport {
  int num_tets = 0;
  int num_vertices = 0;
  int input_faces = 0; ///< faces of the given surface
  int surface_faces = 0; ///< faces of the surface actually meshed (after simplification)
  bool simplified = false; ///< the surface was simplified to reach max_tets
  int holes_filled = 0; ///< boundary loops closed (TetrahedralizeOptions::fill_holes)
  double max_volume = 0; ///< the -a bound of the chosen run (0 = none)
  double seconds = 0; ///< total wall time
  std::vector<TetgenRun> runs; ///< every TetGen run, in order
  std::string tetgen; ///< the program used
};

/// Path of the TetGen program that tetrahedralize() would use for `options`.
std::string tetgen_executable(const TetrahedralizeOptions& options = {});

/// True if that program exists and is executable.
bool tetgen_available(const TetrahedralizeOptions& options = {});

/// Tetrahedralizes a closed, non-self-intersecting triangle surface. `source` names the surface in
/// errors. Throws InputError if the options are invalid, the surface is not closed or encloses no
/// volume (unless fill_holes closes it), TetGen is missing, or TetGen fails (the message then
/// reports how many pairs of faces TetGen found intersecting, from its `-d` check, when that is the
/// cause).
TetMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeOptions& options,
    TetrahedralizeReport* report = nullptr, const std::string& source = "surface");

} // namespace elastolearn::mesh
