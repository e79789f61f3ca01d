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
#include <memory>
#include <string>
#include <vector>

namespace elastolearn::io {

/// A recorded motion of a mesh (tets) or mass-spring system (edges/faces).
struct TrajectoryData {
  Positions rest_positions; ///< n×3 [m]
  Tets tets; ///< m×4 (may be empty)
  Edges edges; ///< e×2 springs (may be empty)
  Faces faces; ///< f×3 triangles for viewing (may be empty)
  std::vector<Positions> positions; ///< T frames, each n×3 [m]
  std::vector<Positions> velocities; ///< empty or T frames [m/s]
  std::vector<double> time; ///< T times [s]
  std::map<std::string, std::string> metadata; ///< string attributes on the root group
};

/// Write atomically (temporary file + rename). Throws InputError naming the path on failure.
void write_trajectory_h5(const std::filesystem::path& path, const TrajectoryData& data);

/// Incremental trajectory writer for long simulations: frames go straight to extendible,
/// compressed datasets in `<path>.tmp-<pid>`; finish() publishes the file by rename. Destroyed
/// without finish() (exception, divergence, Ctrl-C unwinding) it removes the temporary file,
/// unless keep_partial() was called: then it finalises the frames written so far (used to keep
/// the frames before a divergence). Every frame is validated before it is written, so whatever
/// lands on disk passes read_trajectory_h5(). `write_trajectory_h5` is this class in one call.
class TrajectoryWriter {
  public:
  /// Start the file with the rest state (n×3, n ≥ 1, finite) and the optional elements (indices
  /// in [0, n)). Throws InputError naming `path` on invalid data or when the file cannot be made.
  TrajectoryWriter(const std::filesystem::path& path, ConstRef<Positions> rest_positions,
      const Tets& tets = Tets(), const Edges& edges = Edges(), const Faces& faces = Faces());
  ~TrajectoryWriter();
  TrajectoryWriter(TrajectoryWriter&&) noexcept;
  TrajectoryWriter& operator=(TrajectoryWriter&&) noexcept;
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  /// Append one frame: `time` [s] finite and greater than the previous frame's, `positions` n×3
  /// finite [m]. Either every frame has velocities (n×3 [m/s]) or none has. A rejected frame
  /// throws InputError and leaves the file as it was.
  void append(double time, ConstRef<Positions> positions);
  void append(double time, ConstRef<Positions> positions, ConstRef<Positions> velocities);

  /// Write `metadata` as root string attributes ("format" is reserved), close the file and move
  /// it onto the target path. Throws InputError; afterwards the writer accepts nothing more.
  void finish(const std::map<std::string, std::string>& metadata = {});

  /// On destruction without finish(), publish the frames written so far with `metadata`
  /// (plus `status = "partial"` unless given) instead of discarding them.
  void keep_partial(std::map<std::string, std::string> metadata = {});

  /// Frames appended so far.
  long frames() const;
  /// The target path.
  const std::filesystem::path& path() const;

  private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// Read and validate (shapes consistent, indices in range, finite values).
/// Throws InputError naming the file and dataset on any problem.
TrajectoryData read_trajectory_h5(const std::filesystem::path& path);

/// One recorded state of a trajectory file.
struct TrajectoryFrame {
  long index = 0; ///< frame index in [0, frames)
  long frames = 0; ///< T, the number of frames in the file
  double time = 0; ///< [s]
  Positions rest_positions; ///< n×3 [m]
  Positions positions; ///< n×3 [m]
  Positions velocities; ///< n×3 [m/s], or empty when the file has no /velocities
};

/// The number of frames T of a trajectory file (its format and /time checked). Throws
/// InputError naming the file and dataset.
long read_trajectory_frame_count(const std::filesystem::path& path);

/// Read frame `index` (0 ≤ index < T) without loading the other frames. What is read is
/// validated as by read_trajectory_h5 (format, shapes, increasing times, finite values).
/// Throws InputError naming the file and dataset, also for an index out of range.
TrajectoryFrame read_trajectory_frame(const std::filesystem::path& path, long index);

/// Write one VTU per frame (`<stem>_NNNN.vtu`, VTK XML UnstructuredGrid, ASCII-free binary
/// appended data not required: base64 inline) and `<stem>.pvd` indexing them with their times,
/// into `directory`. Cells: tets (VTK_TETRA), else faces (VTK_TRIANGLE), else edges (VTK_LINE).
/// Point data: displacement (and velocity when present). Returns the path of the .pvd.
std::filesystem::path write_vtu_series(
    const std::filesystem::path& directory, const std::string& stem, const TrajectoryData& data);

} // namespace elastolearn::io
