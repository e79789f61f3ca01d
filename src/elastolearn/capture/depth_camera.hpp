#pragma once
/// \file A pinhole depth camera (the virtual stand-in for a Kinect-like sensor, paper 000 §7):
/// pose, resolution and intrinsics, and the ray of each pixel. Conventions as OpenCV's: camera
/// x right, y down, z forward (the optical axis); pixel (u, v) is column u, row v, its centre at
/// (u + ½, v + ½); a point at camera coordinates (x, y, z) projects to
/// (fx·x/z + cx, fy·y/z + cy). Depth is z, the distance along the optical axis (what a depth
/// image stores), not the distance to the eye. Read from JSON by io/camera_file.hpp.
#include <elastolearn/core/types.hpp>

#include <limits>
#include <string>

namespace elastolearn::capture {

struct DepthCamera {
  std::string name; ///< for messages and metadata
  Vec3 position = Vec3::Zero(); ///< eye [m], world coordinates
  /// Columns: the camera's x (right), y (down), z (forward) axes in world coordinates
  /// (orthonormal, right-handed).
  Mat3 rotation = Mat3::Identity();
  int width = 640; ///< pixels
  int height = 480; ///< pixels
  double fx = 525, fy = 525; ///< focal lengths [pixels]
  double cx = 320, cy = 240; ///< principal point [pixels]
  double near = 0; ///< depths below this return nothing [m]
  double far = std::numeric_limits<double>::infinity(); ///< depths above this return nothing [m]

  /// The camera at `position` looking at `target`, with `up` (world) appearing up in the image
  /// (camera −y is the part of `up` orthogonal to the viewing direction). Throws
  /// InputError(source, ...) if target = position or up is parallel to the viewing direction.
  void look_at(const Vec3& target, const Vec3& up, const std::string& source);
  /// Square pixels, principal point at the image centre, vertical field of view `fov_y_deg`
  /// (0, 180) degrees: fy = fx = (height/2) / tan(fov_y/2).
  void set_field_of_view(double fov_y_deg);

  /// World direction of the ray through the centre of pixel (u, v), scaled so that its
  /// component along the optical axis is 1: the point at depth z on the ray is position + z·d.
  Vec3 pixel_ray(int u, int v) const {
    return rotation * Vec3((u + 0.5 - cx) / fx, (v + 0.5 - cy) / fy, 1.0);
  }
  /// The optical axis (camera z) in world coordinates.
  Vec3 forward() const { return rotation.col(2); }
  long long num_pixels() const { return static_cast<long long>(width) * height; }

  /// Check the fields: finite position, orthonormal right-handed rotation (within 1e-9), width and
  /// height in [1, 16384], positive finite focal lengths, finite principal point,
  /// 0 ≤ near < far. Throws InputError("<source>: <field>", ...).
  void validate(const std::string& source) const;
};

} // namespace elastolearn::capture
