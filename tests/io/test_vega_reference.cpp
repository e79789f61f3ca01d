// The standard model against Vega FEM 4.0 (the library paper 000 used for its ground truth): the
// scene file tests/data/vega/neohookean_droop.json (neo-Hookean, consistent mass, Rayleigh damping
// with the exact tangent) reproduces Vega's trajectory of the same scene
// (tests/data/vega/README.md).
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace elastolearn;

namespace {

const std::filesystem::path kVegaDir = std::filesystem::path(ELASTOLEARN_TEST_DATA_DIR) / "vega";

/// Frames of a `VEGATRJ1` file (README.md): each a flat 3n vector of positions.
struct VegaTrajectory {
  int vertices = 0;
  double frame_time = 0; ///< [s] between stored frames
  std::vector<VecX> frames;
};

VegaTrajectory read_vega_trajectory(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << path;
  char magic[8];
  std::int32_t n = 0, count = 0;
  VegaTrajectory t;
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(&n), 4);
  in.read(reinterpret_cast<char*>(&count), 4);
  in.read(reinterpret_cast<char*>(&t.frame_time), 8);
  EXPECT_EQ(std::string(magic, 8), "VEGATRJ1");
  t.vertices = n;
  for (int k = 0; k < count; ++k) {
    VecX x(3 * n);
    in.read(
        reinterpret_cast<char*>(x.data()), static_cast<std::streamsize>(sizeof(double) * 3 * n));
    t.frames.push_back(x);
  }
  EXPECT_TRUE(in) << path << ": truncated";
  return t;
}

std::vector<int> read_fixed(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string comment;
  std::getline(in, comment);
  int count = 0;
  in >> count;
  std::vector<int> ids(count);
  for (int& id : ids)
    in >> id;
  EXPECT_TRUE(in) << path;
  return ids;
}

double max_vertex_distance(const VecX& a, const VecX& b) {
  return (a - b).reshaped(3, a.size() / 3).colwise().norm().maxCoeff();
}

} // namespace

TEST(VegaReference, ExactRayleighDampingAndConsistentMassReproduceVegaToAMicrometre) {
  const io::SceneFile file = io::read_scene_file(kVegaDir / "neohookean_droop.json");
  const sim::Scene& scene = file.scene;
  ASSERT_EQ(scene.mass, fem::MassType::Consistent);
  ASSERT_EQ(scene.material.damping->tangent(), material::DampingTangent::Exact);
  // The scene's {"min": "x"} clamps exactly Vega's vertices.
  std::vector<int> fixed = read_fixed(kVegaDir / "bar1536.fixed");
  std::sort(fixed.begin(), fixed.end());
  ASSERT_EQ(scene.fixed_vertices, fixed);

  const VegaTrajectory vega
      = read_vega_trajectory(kVegaDir / "neohookean_droop_first100_every10.bin");
  ASSERT_EQ(vega.vertices, scene.mesh.num_vertices());
  const int stride = static_cast<int>(std::lround(vega.frame_time / scene.dt));
  ASSERT_EQ(stride * (static_cast<int>(vega.frames.size()) - 1), scene.frames);

  sim::Simulator simulator(scene);
  ASSERT_TRUE(simulator.apply_initial_condition().converged);
  EXPECT_EQ(max_vertex_distance(simulator.positions(), vega.frames[0]), 0.0);
  double worst = 0;
  for (size_t k = 1; k < vega.frames.size(); ++k) {
    for (int s = 0; s < stride; ++s) {
      const auto report = simulator.step();
      ASSERT_TRUE(report.converged) << "step " << simulator.step_index() << ": " << report.message;
    }
    const double d = max_vertex_distance(simulator.positions(), vega.frames[k]);
    worst = std::max(worst, d);
    // Vega's Newton tolerance (1e-8 relative) moves its result by ~1e-9 m (README): 1e-6 m, on a
    // 0.4 m bar whose tip has sagged 6.3 cm by frame 100, leaves room only for round-off.
    EXPECT_LE(d, 1e-6) << "frame " << k * stride;
  }
  char worst_text[32];
  std::snprintf(worst_text, sizeof worst_text, "%.3e", worst);
  RecordProperty("max_vertex_distance_m", worst_text);
}

TEST(VegaReference, TheFlipFreeTangentOrLumpedMassIsADifferentModel) {
  // The same scene with either of elastolearn's other choices is measurably off Vega's, so the
  // test above does check the exact tangent and the consistent mass.
  const io::SceneFile file = io::read_scene_file(kVegaDir / "neohookean_droop.json");
  const VegaTrajectory vega
      = read_vega_trajectory(kVegaDir / "neohookean_droop_first100_every10.bin");
  auto distance_at_frame_100 = [&](sim::Scene scene) {
    sim::Simulator simulator(scene);
    simulator.apply_initial_condition();
    for (int s = 0; s < scene.frames; ++s)
      EXPECT_TRUE(simulator.step().converged);
    return max_vertex_distance(simulator.positions(), vega.frames.back());
  };
  sim::Scene flip_free = file.scene;
  auto damping = flip_free.material.damping->clone();
  damping->set_tangent(material::DampingTangent::FlipFree);
  flip_free.material.damping = std::move(damping);
  const double flip_free_distance = distance_at_frame_100(flip_free);
  EXPECT_GT(flip_free_distance, 1e-5);
  sim::Scene lumped = file.scene;
  lumped.mass = fem::MassType::Lumped;
  const double lumped_distance = distance_at_frame_100(lumped);
  EXPECT_GT(lumped_distance, 1e-5);
  RecordProperty("flip_free_distance_m", std::to_string(flip_free_distance));
  RecordProperty("lumped_distance_m", std::to_string(lumped_distance));
}
