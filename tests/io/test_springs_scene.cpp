#include <elastolearn/core/error.hpp>
#include <elastolearn/io/springs_scene.hpp>

#include "io_test_util.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace elastolearn;
using nlohmann::json;

namespace {
json cloth_scene() {
  return json::parse(R"({
    "format": "elastolearn-springs-scene/1",
    "name": "test cloth",
    "system": {"type": "cloth", "columns": 4, "rows": 3, "plane": "horizontal", "pins": "top-corners"},
    "spring": {"law": "linear", "k": 500, "c": 0.5},
    "simulation": {"mode": "implicit", "dt": 0.01, "steps": 20},
    "gravity": [0, -9.81, 0],
    "loads": [{"nodes": [10, 11], "force": [0, -2, 0]}],
    "output": {"trajectory": "cloth.h5", "every": 2}
  })");
}

/// The InputError message of parsing `j`, or "" if it parsed.
std::string parse_error(const json& j) {
  try {
    io::parse_springs_scene(j, "scene.json", "/base");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
} // namespace

TEST(SpringsScene, ParsesACloth) {
  const io::SpringsScene scene = io::parse_springs_scene(cloth_scene(), "scene.json", "/base");
  EXPECT_EQ(scene.system.node_count(), 12);
  EXPECT_EQ(scene.system_type, "cloth");
  EXPECT_EQ(scene.simulation.mode, springs::LearnedMode::corrected_implicit);
  EXPECT_EQ(scene.steps, 20);
  EXPECT_DOUBLE_EQ(scene.training.law.k, 500.0);
  EXPECT_DOUBLE_EQ(scene.loads.forces(10, 1), -2.0);
  EXPECT_DOUBLE_EQ(scene.loads.gravity.y(), -9.81);
  ASSERT_TRUE(scene.trajectory.has_value());
  EXPECT_EQ(*scene.trajectory, std::filesystem::path("/base/cloth.h5"));
  EXPECT_EQ(scene.every, 2);
  EXPECT_TRUE(scene.system.pinned[0] && scene.system.pinned[3]);
}

TEST(SpringsScene, BadFieldsGiveErrorsNamingTheField) {
  struct Case {
    const char* pointer;
    json value;
    const char* expected; // substring of the message
  };
  const Case cases[] = {
    { "/format", "elastolearn-scene/1", "format" }, { "/system/type", "net", "system.type" },
    { "/system/columns", 1, "system.columns" }, { "/spring/k", -5, "spring.k" },
    { "/spring/law", "quartic", "spring.law" }, { "/simulation/mode", "magic", "simulation.mode" },
    { "/simulation/dt", 0, "simulation.dt" }, { "/simulation/steps", 0, "simulation.steps" },
    { "/loads/0/nodes", json::array({ 99 }), "loads[0].nodes" },
    { "/gravity", json::array({ 0, 1 }), "gravity" }, { "/output/every", 0, "output.every" },
    { "/spring/kk", 3, "spring" }, // unknown key (typo)
  };
  for (const Case& c : cases) {
    json j = cloth_scene();
    j[json::json_pointer(c.pointer)] = c.value;
    const std::string message = parse_error(j);
    EXPECT_NE(message.find("scene.json"), std::string::npos) << c.pointer << ": " << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.pointer << ": " << message;
  }
  json j = cloth_scene();
  j["system"].erase("columns");
  EXPECT_NE(parse_error(j).find("system.columns"), std::string::npos) << parse_error(j);
  // A spring too stiff for the paper's trajectory data at this dt: a clear error, not NaNs.
  j = cloth_scene();
  j["spring"]["k"] = 1e6;
  EXPECT_NE(parse_error(j).find("phase-grid"), std::string::npos) << parse_error(j);
}

TEST(SpringsScene, LearnedSpringRoundTrips) {
  springs::TrainingOptions t;
  t.law.kind = springs::SpringLawKind::cubic;
  t.law.k = 100;
  t.law.k3 = 50;
  springs::LearnOptions o;
  o.features.degree = 3;
  const springs::LearnedSpring spring = springs::learn_spring(t, o);
  const io::test::ScratchDir scratch;
  const auto path = scratch / "learned_spring.json";
  io::write_learned_spring(path, spring, &t.law);
  const springs::LearnedSpring back = io::read_learned_spring(path);
  EXPECT_EQ(back.features().degree, 3);
  EXPECT_DOUBLE_EQ(back.dt(), spring.dt());
  // JSON numbers round-trip doubles exactly (nlohmann writes 17 significant digits).
  EXPECT_EQ((back.coefficients() - spring.coefficients()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(back.force(0.2, 0.1), spring.force(0.2, 0.1));
}

TEST(SpringsScene, BadLearnedSpringFileNamesTheField) {
  json j = io::learned_spring_to_json(springs::learn_spring(springs::TrainingOptions {}));
  j["coefficients"].erase(1);
  try {
    io::learned_spring_from_json(j, "spring.json");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spring.json: coefficients"), std::string::npos)
        << e.what();
  }
}

TEST(SpringsScene, ExampleScenesParseAndRun) {
  for (const char* name : { "rope.json", "cloth.json" }) {
    const auto path = std::filesystem::path(ELASTOLEARN_EXAMPLES_DIR) / "05_springs" / name;
    io::SpringsScene scene = io::read_springs_scene(path);
    scene.steps = 5; // smoke run; the examples' full length is for the command line
    auto stepper = io::make_scene_stepper(scene);
    const auto record
        = springs::run_simulation(*stepper, springs::rest_state(scene.system), scene.steps);
    EXPECT_FALSE(record.diverged) << name << ": " << record.message;
    const io::TrajectoryData data = io::springs_trajectory(scene.system, record);
    EXPECT_EQ(data.positions.size(), 6u);
    EXPECT_EQ(data.edges.rows(), scene.system.spring_count());
  }
}
