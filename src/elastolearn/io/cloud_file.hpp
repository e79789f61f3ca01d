#pragma once
/// \file Point-cloud sequence HDF5 files (DESIGN.md "Files and formats", docs/file_formats.md
/// "Point clouds"), readable and writable with h5py:
///   /clouds/points (N, 3) f64       every frame's points [m], frame after frame
///   /clouds/offsets (T+1,) i64      frame t is rows offsets[t] … offsets[t+1]−1 (0 … N)
///   /clouds/normals (N, 3) f64      optional: unit normals, one per point
///   /clouds/confidence (N,) f64     optional: per-point confidence in [0, 1]
///   /time (T,) f64                  frame times [s], evenly spaced by dt
///   root attributes: format = "elastolearn-clouds/1", dt (float64 [s]), plus optional
///   free-form string metadata (scan writes source, cameras, noise_sigma, outliers, seed)
#include <elastolearn/capture/point_cloud.hpp>

#include <filesystem>
#include <map>
#include <memory>
#include <string>

namespace elastolearn::io {

/// Frame-by-frame writer: points go to chunked, compressed datasets in `<path>.tmp-<pid>` as they
/// come, and finish() publishes the file by rename; destroyed without finish() it removes the
/// temporary file. Every frame is validated (CloudFrame::validate) before it is written, so a
/// finished file always passes read_clouds_h5.
class CloudWriter {
  public:
  /// dt > 0 and start_time finite [s]. Throws InputError naming `path`.
  CloudWriter(const std::filesystem::path& path, double dt, double start_time = 0);
  ~CloudWriter();
  CloudWriter(const CloudWriter&) = delete;
  CloudWriter& operator=(const CloudWriter&) = delete;

  /// Append the next frame (may be empty). The first frame with points decides whether the file
  /// has normals and confidence; later frames with points must agree. Throws InputError.
  void append(const capture::CloudFrame& frame);
  /// Write /clouds/offsets, /time and the attributes (`metadata` keys other than "format" and
  /// "dt"), close and rename onto the target. Needs at least one frame. Throws InputError.
  void finish(const std::map<std::string, std::string>& metadata = {});

  long frames() const;
  long long points() const;

  private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// Write a whole sequence atomically (validated first). Throws InputError naming the path.
void write_clouds_h5(const std::filesystem::path& path, const capture::PointCloudSequence& clouds,
    const std::map<std::string, std::string>& metadata = {});

/// Read and validate a point-cloud file: format attribute, shapes ((N, 3), (T+1,), (N, 3), (N,),
/// (T,)), integer offsets from 0 to N that never decrease, finite points, unit normals,
/// confidence in [0, 1], dt positive, /time evenly spaced by dt (1e-6 relative) with T matching
/// the offsets. Throws InputError("<file>: <dataset>", ...) on any problem.
capture::PointCloudSequence read_clouds_h5(const std::filesystem::path& path);

/// The root attributes other than "format" and "dt", as text. Throws InputError like
/// read_clouds_h5.
std::map<std::string, std::string> read_clouds_metadata(const std::filesystem::path& path);

/// The scanner's accuracy σ [m] a cloud file records (its "noise_sigma" attribute, which scan
/// writes), or 0 when it records none. Throws InputError("<file>: / attribute 'noise_sigma'", ...)
/// for a value that is not a non-negative number, and like read_clouds_h5.
double read_clouds_noise_sigma(const std::filesystem::path& path);

/// True if `path` is an HDF5 file whose "format" attribute names elastolearn point clouds (any
/// version); false for anything else, including files that cannot be opened.
bool is_clouds_h5(const std::filesystem::path& path);

} // namespace elastolearn::io
