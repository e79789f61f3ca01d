#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/camera_file.hpp>
#include <elastolearn/io/json_fields.hpp>

#include <cmath>
#include <set>

namespace elastolearn::io {

namespace {

constexpr const char* k_cameras_kind = "elastolearn-cameras";
constexpr int k_cameras_version = 1;

capture::DepthCamera read_camera(const JsonObject& c, int index) {
  // A typo must not fall back to a default (an "upp" would leave "up" at +y).
  c.reject_unknown_keys(
      { "name", "position", "look_at", "up", "resolution", "fov_y", "intrinsics", "near", "far" });
  capture::DepthCamera camera;
  camera.name = c.string("name", "camera" + std::to_string(index));
  camera.position = c.vec3("position");
  const Vec3 target = c.vec3("look_at");
  const Vec3 up = c.vec3("up", Vec3(0, 1, 0));
  const Vec3 view = target - camera.position;
  if (!(view.norm() > 0))
    c.fail("look_at", "equals position: the camera has no viewing direction");
  if (!(view.normalized().cross(up).norm() > 1e-9 * up.norm()))
    c.fail("up", "is zero or parallel to the viewing direction");
  camera.look_at(target, up, c.file() + ": " + c.field(""));
  const std::vector<int> resolution = c.integers("resolution");
  if (resolution.size() != 2 || resolution[0] < 1 || resolution[1] < 1 || resolution[0] > 16384
      || resolution[1] > 16384)
    c.fail("resolution", "expected [width, height] in pixels, each in [1, 16384]");
  camera.width = resolution[0];
  camera.height = resolution[1];
  if (c.has("fov_y") == c.has("intrinsics"))
    c.fail("", "give exactly one of \"fov_y\" (degrees) and \"intrinsics\" {fx, fy, cx, cy}");
  if (c.has("fov_y")) {
    const double fov = c.positive("fov_y");
    if (!(fov < 180))
      c.fail("fov_y", "expected an angle in (0, 180) degrees, got " + to_text(fov));
    camera.set_field_of_view(fov);
  } else {
    const JsonObject k = c.object("intrinsics");
    camera.fx = k.positive("fx");
    camera.fy = k.positive("fy");
    camera.cx = k.number("cx");
    camera.cy = k.number("cy");
    k.reject_unknown_keys({ "fx", "fy", "cx", "cy" });
  }
  camera.near = c.number("near", 0);
  if (camera.near < 0)
    c.fail("near", "expected a depth ≥ 0 [m], got " + to_text(camera.near));
  if (c.has("far")) {
    camera.far = c.positive("far");
    if (!(camera.far > camera.near))
      c.fail("far",
          "must be greater than near (" + to_text(camera.near) + "), got " + to_text(camera.far));
  }
  camera.validate(c.file() + ": " + c.field(""));
  return camera;
}

} // namespace

std::vector<capture::DepthCamera> read_camera_file(const std::filesystem::path& path) {
  const nlohmann::json json = read_json_file(path);
  const JsonObject root(json, path.string());
  check_format(root, k_cameras_kind, k_cameras_version);
  const std::vector<JsonObject> list = root.objects("cameras");
  root.reject_unknown_keys({ "format", "cameras" });
  if (list.empty())
    root.fail("cameras", "expected at least one camera");
  std::vector<capture::DepthCamera> cameras;
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    cameras.push_back(read_camera(list[i], static_cast<int>(i)));
    if (!names.insert(cameras.back().name).second)
      list[i].fail("name", "\"" + cameras.back().name + "\" is used by an earlier camera");
  }
  return cameras;
}

nlohmann::json cameras_to_json(const std::vector<capture::DepthCamera>& cameras) {
  nlohmann::json list = nlohmann::json::array();
  for (const capture::DepthCamera& c : cameras) {
    const Vec3 target = c.position + c.forward();
    const Vec3 up = -c.rotation.col(1);
    nlohmann::json camera
        = { { "name", c.name }, { "position", { c.position.x(), c.position.y(), c.position.z() } },
            { "look_at", { target.x(), target.y(), target.z() } },
            { "up", { up.x(), up.y(), up.z() } }, { "resolution", { c.width, c.height } },
            { "intrinsics", { { "fx", c.fx }, { "fy", c.fy }, { "cx", c.cx }, { "cy", c.cy } } },
            { "near", c.near } };
    if (std::isfinite(c.far))
      camera["far"] = c.far;
    list.push_back(camera);
  }
  return { { "format", std::string(k_cameras_kind) + "/" + std::to_string(k_cameras_version) },
    { "cameras", list } };
}

} // namespace elastolearn::io
