#pragma once
/// \file Trajectory HDF5 files (DESIGN.md "Files and formats"), readable with h5py:
///   /rest_positions (n,3) f64   /positions (T,n,3) f64   /time (T) f64
///   /tets (m,4) i32 [optional]  /edges (e,2) i32 [optional, springs]  /faces (f,3) i32 [optional]
///   /velocities (T,n,3) f64 [optional]
///   root attributes: format = "elastolearn-trajectory/1", plus free-form string metadata
///   (e.g. "scene", "material", "dt", "status").
#include <elastolearn/core/types.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace elastolearn::io {

/// A recorded motion of a mesh (tets) or mass-spring system (edges/faces).
struct TrajectoryData {
  Positions rest_positions;              ///< n×3 [m]
  Tets tets;                             ///< m×4 (may be empty)
  Edges edges;                           ///< e×2 springs (may be empty)
  Faces faces;                           ///< f×3 triangles for viewing (may be empty)
  std::vector<Positions> positions;      ///< T frames, each n×3 [m]
  std::vector<Positions> velocities;     ///< empty or T frames [m/s]
  std::vector<double> time;              ///< T times [s]
  std::map<std::string, std::string> metadata; ///< string attributes on the root group
};

/// Write atomically (temporary file + rename). Throws InputError naming the path on failure.
void write_trajectory_h5(const std::filesystem::path& path, const TrajectoryData& data);

/// Read and validate (shapes consistent, indices in range, finite values).
/// Throws InputError naming the file and dataset on any problem.
TrajectoryData read_trajectory_h5(const std::filesystem::path& path);

/// Write one VTU per frame (`<stem>_NNNN.vtu`, VTK XML UnstructuredGrid, ASCII-free binary
/// appended data not required: base64 inline) and `<stem>.pvd` indexing them with their times,
/// into `directory`. Cells: tets (VTK_TETRA), else faces (VTK_TRIANGLE), else edges (VTK_LINE).
/// Point data: displacement (and velocity when present). Returns the path of the .pvd.
std::filesystem::path write_vtu_series(const std::filesystem::path& directory,
                                       const std::string& stem, const TrajectoryData& data);

} // namespace elastolearn::io
