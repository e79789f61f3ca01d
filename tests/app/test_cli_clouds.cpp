// End-to-end: `simulate` → `scan` → a point-cloud file whose points lie on the simulated
// surface, the same for the same seed; `import-clouds` of a folder of PLY and XYZ frames in
// natural order; `info` of the result.
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <support/cli_runner.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

using namespace elastolearn;

namespace {

using elastolearn::test::run;
class CliCloudsTest : public elastolearn::test::CliTestFolder {
  protected:
  /// "'<folder>/": the start of a quoted path in the test's folder (the caller closes the quote).
  std::string quoted_folder() const {
    std::string d = m_dir.string();
    d.insert(d.begin(), '\'');
    d.push_back('/');
    return d;
  }
};

/// A bar swinging under gravity, 6 frames.
const char* kSwingingBar = R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [4, 1, 1]},
  "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000},
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 0.01, "frames": 5}
})";

/// Two cameras: above and in front of the bar.
const char* kTwoCameras = R"({"format": "elastolearn-cameras/1", "cameras": [
  {"name": "top", "position": [0.1, 0.6, 0.025], "look_at": [0.1, 0, 0.025], "up": [0, 0, -1],
   "resolution": [64, 48], "fov_y": 30},
  {"name": "front", "position": [0.1, 0.0, 0.6], "look_at": [0.1, 0, 0], "resolution": [64, 48],
   "intrinsics": {"fx": 120, "fy": 120, "cx": 32, "cy": 24}, "near": 0.1, "far": 2}]})";

/// Distance from p to the triangle (a, b, c): to its plane when p projects inside it, else to
/// the nearest edge.
double distance_to_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const Vec3 q = p - n.dot(p - a) * n;
  const auto inside
      = [&](const Vec3& u, const Vec3& v) { return (v - u).cross(q - u).dot(n) >= 0; };
  if (inside(a, b) && inside(b, c) && inside(c, a))
    return std::abs(n.dot(p - a));
  const auto segment = [&](const Vec3& u, const Vec3& v) {
    const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    return (p - (u + t * (v - u))).norm();
  };
  return std::min({ segment(a, b), segment(b, c), segment(c, a) });
}

} // namespace

TEST_F(CliCloudsTest, ScanPutsEveryPointOnTheSimulatedSurfaceAndRepeatsForASeed) {
  write("bar.json", kSwingingBar);
  write("cam.json", kTwoCameras);
  const std::string d = quoted_folder();
  auto r = run("simulate " + d + "bar.json' -o " + d + "bar.h5' -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("scan " + d + "bar.h5' --camera " + d + "cam.json' -q --normals -o " + d + "c.h5'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("scanned 6 frames with 2 cameras"), std::string::npos) << r.output;

  const io::TrajectoryData traj = io::read_trajectory_h5(m_dir / "bar.h5");
  const mesh::TetMesh bar(traj.rest_positions, traj.tets, "bar");
  const capture::PointCloudSequence clouds = io::read_clouds_h5(m_dir / "c.h5");
  ASSERT_EQ(clouds.num_frames(), 6);
  EXPECT_EQ(clouds.dt, 0.01);
  EXPECT_TRUE(clouds.has_normals());
  const auto metadata = io::read_clouds_metadata(m_dir / "c.h5");
  EXPECT_NE(metadata.at("cameras").find("\"front\""), std::string::npos);
  for (int t = 0; t < clouds.num_frames(); ++t) {
    const auto points = clouds.frame_points(t);
    ASSERT_GT(points.rows(), 300) << t;
    const Positions& x = traj.positions[static_cast<std::size_t>(t)];
    const Faces& faces = bar.surface_faces();
    for (Eigen::Index i = 0; i < points.rows(); i += 7) {
      double nearest = 1e9;
      for (Eigen::Index f = 0; f < faces.rows(); ++f)
        nearest = std::min(nearest,
            distance_to_triangle(points.row(i).transpose(), x.row(faces(f, 0)).transpose(),
                x.row(faces(f, 1)).transpose(), x.row(faces(f, 2)).transpose()));
      EXPECT_LT(nearest, 1e-12) << "frame " << t << " point " << i; // no noise asked
    }
  }

  // Noise and outliers: the same seed gives the same file contents, another seed does not.
  const std::string noisy = " --camera " + d + "cam.json' -q --noise 0.001 --outliers 0.1";
  ASSERT_EQ(run("scan " + d + "bar.h5'" + noisy + " --seed 3 -o " + d + "a.h5'").exit_code, 0);
  ASSERT_EQ(run("scan " + d + "bar.h5'" + noisy + " --seed 3 -o " + d + "b.h5'").exit_code, 0);
  ASSERT_EQ(run("scan " + d + "bar.h5'" + noisy + " --seed 4 -o " + d + "e.h5'").exit_code, 0);
  const auto a = io::read_clouds_h5(m_dir / "a.h5"), b = io::read_clouds_h5(m_dir / "b.h5"),
             e = io::read_clouds_h5(m_dir / "e.h5");
  EXPECT_EQ(a.points, b.points);
  ASSERT_EQ(a.points.rows(), e.points.rows());
  EXPECT_NE(a.points, e.points);
}

TEST_F(CliCloudsTest, ImportCloudsReadsAFolderInNaturalOrder) {
  std::filesystem::create_directory(m_dir / "scans");
  write("scans/frame_10.xyz", "# an empty frame: nothing seen\n");
  write("scans/frame_2.ply",
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty "
      "float z\nproperty uchar red\nend_header\n2 0 0 255\n");
  write("scans/frame_1.xyz", "1 0 0\n1 1 0\n");
  const std::string d = quoted_folder();
  auto r = run("import-clouds " + d + "scans' --dt 0.04 -o " + d + "c.h5'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("imported 3 frames (frame_1.xyz .. frame_10.xyz)"), std::string::npos)
      << r.output;
  const auto clouds = io::read_clouds_h5(m_dir / "c.h5");
  EXPECT_EQ(clouds.offsets, (std::vector<Eigen::Index> { 0, 2, 3, 3 }));
  EXPECT_EQ(clouds.points(2, 0), 2); // frame_2.ply second
  r = run("info " + d + "c.h5'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("point clouds: 3 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 empty"), std::string::npos) << r.output;
}
