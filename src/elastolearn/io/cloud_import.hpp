#pragma once
/// \file Point clouds as scanning tools export them: one file per frame, PLY or XYZ text, in a
/// folder (docs/file_formats.md, "Point clouds from scanning tools"). `elastolearn import-clouds`
/// turns such a folder into one point-cloud HDF5 file (io/cloud_file.hpp).
///
/// - `.ply`: ASCII or binary little-endian; element `vertex` with properties x, y, z (any numeric
///   type) and optionally nx, ny, nz (unit normals) and confidence (in [0, 1]); other properties
///   (colours, …) and other elements (faces, …) are skipped.
/// - `.xyz`: text, one point per line: `x y z`, `x y z confidence`, `x y z nx ny nz` or
///   `x y z nx ny nz confidence` (white space or commas between numbers), the same number of
///   columns on every line; `#` starts a comment.
/// A file without points is an empty frame.
#include <elastolearn/capture/point_cloud.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// One frame from a .ply or .xyz file (extension case-insensitive). Throws InputError naming the
/// file (and line, for text) for unreadable or truncated files, a token that is not a number,
/// NaN/inf, a normal that is not a unit vector (e.g. colours in the normal columns), a
/// confidence outside [0, 1], a line with a different number of columns, or another extension.
capture::CloudFrame read_point_cloud_file(const std::filesystem::path& path);

/// Natural order of names: digit runs compare as numbers ("frame_2" < "frame_10"), the rest
/// byte by byte; equal numbers with more leading zeros come first ("01" < "1"), so the order is
/// total.
bool natural_less(const std::string& a, const std::string& b);

/// The .ply and .xyz files directly in `folder`, in natural order of their names. Throws
/// InputError(folder, ...) if it is missing, not a folder, or holds no such file.
std::vector<std::filesystem::path> list_point_cloud_files(const std::filesystem::path& folder);

/// Read the cloud files of `folder` (list_point_cloud_files) in order, handing each frame to
/// `sink(file, frame)` as it is read, so that a long capture never has to fit in memory. Frames
/// with points must agree on having normals and confidence (capture::FrameLayout); the error
/// names the first file that does not. Throws InputError.
void read_point_cloud_folder(const std::filesystem::path& folder,
    const std::function<void(const std::filesystem::path& file, const capture::CloudFrame& frame)>&
        sink);

/// Every cloud file of `folder` as one frame of a sequence, frames dt [s] apart from start_time
/// [s] (read_point_cloud_folder, in memory). Throws InputError.
capture::PointCloudSequence import_point_clouds(
    const std::filesystem::path& folder, double dt, double start_time = 0);

} // namespace elastolearn::io
