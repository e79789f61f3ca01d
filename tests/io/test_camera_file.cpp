// Depth-camera files: one or several cameras, field of view or intrinsics, errors naming the field.
#include "io_test_util.hpp"

#include <elastolearn/io/camera_file.hpp>
#include <elastolearn/io/json_fields.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

using namespace elastolearn;
using namespace elastolearn::io;
using elastolearn::io::test::expect_input_error;
using elastolearn::io::test::ScratchDir;

namespace {

const std::string kTwo = R"({"format": "elastolearn-cameras/1", "cameras": [
  {"name": "front", "position": [0, 0, 2], "look_at": [0, 0, 0], "resolution": [640, 480],
   "fov_y": 60, "near": 0.5, "far": 4},
  {"position": [2, 0, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "resolution": [320, 240],
   "intrinsics": {"fx": 300, "fy": 310, "cx": 160.5, "cy": 119.5}}]})";

std::string replaced(const std::string& from, const std::string& to) {
  std::string text = kTwo;
  text.replace(text.find(from), from.size(), to);
  return text;
}

} // namespace

TEST(CameraFile, ReadsFieldOfViewAndIntrinsicsCameras) {
  ScratchDir dir;
  std::ofstream(dir / "cam.json") << kTwo;
  const auto cameras = read_camera_file(dir / "cam.json");
  ASSERT_EQ(cameras.size(), 2u);
  const auto& a = cameras[0];
  EXPECT_EQ(a.name, "front");
  EXPECT_EQ(a.width, 640);
  EXPECT_NEAR(a.fy, 240 / std::tan(std::numbers::pi / 6), 1e-9);
  EXPECT_EQ(a.fx, a.fy);
  EXPECT_EQ(a.cx, 320);
  EXPECT_EQ(a.near, 0.5);
  EXPECT_EQ(a.far, 4);
  EXPECT_NEAR(a.forward().z(), -1, 1e-15);
  const auto& b = cameras[1];
  EXPECT_EQ(b.name, "camera1");
  EXPECT_EQ(b.fy, 310);
  EXPECT_EQ(b.cx, 160.5);
  EXPECT_TRUE(std::isinf(b.far));
  EXPECT_NEAR(-b.rotation.col(1).z(), 1, 1e-15); // "up": +z appears up
  // What scan records reads back as the same cameras.
  std::ofstream(dir / "again.json") << cameras_to_json(cameras).dump();
  const auto again = read_camera_file(dir / "again.json");
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LT((again[i].rotation - cameras[i].rotation).norm(), 1e-12);
    EXPECT_EQ(again[i].fx, cameras[i].fx);
    EXPECT_EQ(again[i].far, cameras[i].far);
  }
}

TEST(CameraFile, TheExampleFileReads) {
  const auto cameras = read_camera_file(
      std::filesystem::path(ELASTOLEARN_EXAMPLES_DIR) / "06_point_clouds" / "cameras.json");
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[1].name, "oblique");
  EXPECT_EQ(cameras[1].width, 512);
}

TEST(CameraFile, ErrorsNameTheField) {
  ScratchDir dir;
  const auto rejected = [&](const std::string& text, const std::vector<std::string>& parts) {
    std::ofstream(dir / "cam.json") << text;
    expect_input_error([&] { read_camera_file(dir / "cam.json"); }, parts);
  };
  rejected(
      replaced("\"fov_y\": 60", "\"fov_y\": 190"), { "cam.json: cameras[0].fov_y", "(0, 180)" });
  rejected(replaced("\"fov_y\": 60,", "\"fov_y\": 60, \"intrinsics\": {},"),
      { "cameras[0]", "exactly one of" });
  rejected(replaced("[640, 480]", "[640, 0]"), { "cameras[0].resolution" });
  rejected(replaced("[640, 480]", "[640]"), { "cameras[0].resolution" });
  rejected(replaced("\"look_at\": [0, 0, 0], \"res", "\"look_at\": [0, 0, 2], \"res"),
      { "cameras[0].look_at", "equals position" });
  rejected(replaced("\"up\": [0, 0, 1]", "\"up\": [1, 0, 0]"), { "cameras[1].up", "parallel" });
  rejected(replaced("\"near\": 0.5", "\"near\": -1"), { "cameras[0].near" });
  rejected(replaced("\"far\": 4", "\"far\": 0.25"), { "cameras[0].far", "greater than near" });
  rejected(replaced("\"fx\": 300", "\"fx\": -300"), { "cameras[1].intrinsics.fx" });
  rejected(replaced("\"name\": \"front\"", "\"name\": \"camera1\""),
      { "cameras[1].name", "earlier camera" });
  rejected(replaced("\"near\": 0.5", "\"naer\": 0.5"), { "cameras[0].naer", "unknown field" });
  rejected(R"({"format": "elastolearn-cameras/1", "cameras": []})",
      { "cam.json: cameras", "at least one" });
  rejected(R"({"format": "elastolearn-scene/1", "cameras": []})", { "cam.json: format" });
}
