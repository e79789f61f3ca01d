#include <elastolearn/capture/depth_camera.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <cmath>
#include <numbers>

namespace elastolearn::capture {

void DepthCamera::look_at(const Vec3& target, const Vec3& up, const std::string& source) {
  const Vec3 z = target - position;
  if (!(z.norm() > 0))
    throw InputError(source, "look_at equals position: the camera has no viewing direction");
  const Vec3 forward = z.normalized();
  const Vec3 y = -(up - up.dot(forward) * forward); // image down = −(up ⊥ forward)
  if (!(y.norm() > 1e-9 * up.norm()) || !(up.norm() > 0))
    throw InputError(source, "up is zero or parallel to the viewing direction");
  rotation.col(2) = forward;
  rotation.col(1) = y.normalized();
  rotation.col(0) = rotation.col(1).cross(rotation.col(2));
}

void DepthCamera::set_field_of_view(double fov_y_deg) {
  fy = fx = 0.5 * height / std::tan(0.5 * fov_y_deg * std::numbers::pi / 180);
  cx = 0.5 * width;
  cy = 0.5 * height;
}

void DepthCamera::validate(const std::string& source) const {
  const auto fail = [&](const std::string& field, const std::string& what) {
    throw InputError(source + ": " + field, what);
  };
  if (!position.allFinite())
    fail("position", "must be finite");
  if (!rotation.allFinite() || !(rotation.transpose() * rotation).isIdentity(1e-9)
      || !(rotation.determinant() > 0))
    fail("rotation", "must be a rotation matrix (orthonormal, determinant +1)");
  if (width < 1 || width > 16384 || height < 1 || height > 16384)
    fail("resolution",
        "width and height must be in [1, 16384], got " + std::to_string(width) + " × "
            + std::to_string(height));
  if (!(std::isfinite(fx) && fx > 0 && std::isfinite(fy) && fy > 0))
    fail("intrinsics", "focal lengths must be positive, got " + to_text(fx) + ", " + to_text(fy));
  if (!std::isfinite(cx) || !std::isfinite(cy))
    fail("intrinsics", "principal point must be finite");
  if (!(near >= 0 && std::isfinite(near)))
    fail("near", "must be finite and ≥ 0, got " + to_text(near));
  if (!(far > near))
    fail("far", "must be greater than near (" + to_text(near) + "), got " + to_text(far));
}

} // namespace elastolearn::capture
