#pragma once
/// \file Depth-camera files (JSON, docs/file_formats.md "Depth cameras"): one or more cameras for
/// the virtual scanner (`elastolearn scan`):
///   {"format": "elastolearn-cameras/1",
///    "cameras": [{"name": "front", "position": [0, 0, 1], "look_at": [0, 0, 0], "up": [0, 1, 0],
///                 "resolution": [640, 480], "fov_y": 45, "near": 0.1, "far": 5}]}
/// with either "fov_y" (vertical field of view, degrees) or "intrinsics" {"fx", "fy", "cx",
/// "cy"} (pixels, OpenCV's pinhole model).
#include <elastolearn/capture/depth_camera.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

namespace elastolearn::io {

/// Read and validate the cameras of a file (at least one; names unique, "camera<i>" when not
/// given). Errors name the file and the field ("cam.json: cameras[1].fov_y: …"). Throws
/// InputError.
std::vector<capture::DepthCamera> read_camera_file(const std::filesystem::path& path);

/// The cameras as a camera file's JSON (intrinsics written explicitly, pose as position, look_at
/// one metre ahead and up): what `scan` records in its output's metadata.
nlohmann::json cameras_to_json(const std::vector<capture::DepthCamera>& cameras);

} // namespace elastolearn::io
