// Training-set files (several motions of one object): a written set reads back with the same
// scenes and observations from any working folder, and every malformed set is refused with an
// error naming the file and the field.
#include "io_test_util.hpp"

#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <gtest/gtest.h>

#include <fstream>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;
using Json = nlohmann::json;

namespace {

/// A clamped box bar of `cells` along x, `frames` steps of 10 ms, with one shared material.
Json scene_json(int cells, int frames) {
  Json j = Json::parse(R"({
    "format": "elastolearn-scene/1",
    "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [4, 1, 1]},
    "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000,
                 "damping": {"alpha0": 0, "alpha1": 0.01}},
    "gravity": [0, -9.81, 0],
    "fixed": [{"min": "x"}],
    "time": {"dt": 0.01, "frames": 5}
  })");
  j["mesh"]["cells"][0] = cells;
  j["time"]["frames"] = frames;
  return j;
}

void write_json(const std::filesystem::path& path, const Json& json) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << json.dump(2);
}

/// Observations of the `stride`-th vertices of `scene` (frames + 1 frames of its dt), moving
/// down by 1 mm per frame plus `offset`, so that two files differ.
observe::Observation observation_of(const sim::Scene& scene, double offset) {
  observe::Observation obs;
  obs.dt = scene.dt;
  for (int v = 0; v < scene.mesh.num_vertices(); v += 3)
    obs.vertex_ids.push_back(v);
  const Positions rest = scene.mesh.rest_positions();
  for (int t = 0; t <= scene.frames; ++t) {
    Positions x(obs.num_observed(), 3);
    for (int j = 0; j < obs.num_observed(); ++j)
      x.row(j) = rest.row(obs.vertex_ids[j]) + Eigen::RowVector3d(0, -1e-3 * t + offset, 0);
    obs.positions.push_back(x);
  }
  return obs;
}

/// Writes `scene` JSON to `scene_path` and observations of it to `observations_path`.
void write_motion(const std::filesystem::path& scene_path,
    const std::filesystem::path& observations_path, const Json& scene, double offset) {
  write_json(scene_path, scene);
  std::filesystem::create_directories(observations_path.parent_path());
  write_observation_h5(
      observations_path, observation_of(read_scene_file(scene_path).scene, offset));
}

/// Two motions: a.json / a.h5 (4 cells, 5 frames) and motions/b.json / motions/b.h5 (a finer
/// mesh, 7 frames) in `dir`.
std::vector<TrainingSetEntry> two_motions(const ScratchDir& dir) {
  write_motion(dir / "a.json", dir / "a.h5", scene_json(4, 5), 0);
  write_motion(dir / "motions/b.json", dir / "motions/b.h5", scene_json(6, 7), 1e-3);
  return { { dir / "a.json", dir / "a.h5" }, { dir / "motions/b.json", dir / "motions/b.h5" } };
}

void expect_same_observation(const observe::Observation& a, const observe::Observation& b) {
  EXPECT_EQ(a.vertex_ids, b.vertex_ids);
  EXPECT_EQ(a.dt, b.dt);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (size_t t = 0; t < a.positions.size(); ++t)
    EXPECT_EQ(a.positions[t], b.positions[t]) << "frame " << t;
}

bool has_input(const TrainingSet& set, const std::filesystem::path& path) {
  for (const CommandInput& input : set.inputs)
    if (same_file(input.path, path))
      return true;
  return false;
}

/// Changes the working folder for the lifetime of the object.
class WorkingFolder {
  public:
  explicit WorkingFolder(const std::filesystem::path& folder)
      : m_previous(std::filesystem::current_path()) {
    std::filesystem::create_directories(folder);
    std::filesystem::current_path(folder);
  }
  ~WorkingFolder() { std::filesystem::current_path(m_previous); }

  private:
  std::filesystem::path m_previous;
};

/// A training-set document with one motion per (scene, observations) pair.
Json set_json(const std::vector<std::pair<std::string, std::string>>& motions) {
  Json entries = Json::array();
  for (const auto& [scene, observations] : motions)
    entries.push_back({ { "scene", scene }, { "observations", observations } });
  return { { "format", "elastolearn-training/1" }, { "motions", entries } };
}

} // namespace

TEST(TrainingSet, RoundTripsScenesAndObservations) {
  const ScratchDir dir;
  const std::vector<TrainingSetEntry> entries = two_motions(dir);
  write_training_set(dir / "set.json", entries);
  // Paths are stored relative to the set's folder, and no temporary file is left behind.
  const Json written = read_json_file(dir / "set.json");
  EXPECT_EQ(written["motions"][0]["scene"], "a.json");
  EXPECT_EQ(written["motions"][1]["observations"], "motions/b.h5");
  EXPECT_EQ(dir.files().size(), 4u); // a.json, a.h5, motions/, set.json

  const TrainingSet set = read_training_set(dir / "set.json");
  ASSERT_EQ(set.motions.size(), 2u);
  ASSERT_EQ(set.files.size(), 2u);
  for (size_t i = 0; i < entries.size(); ++i) {
    const SceneFile expected = read_scene_file(entries[i].scene);
    const sim::Scene& scene = set.motions[i].scene;
    EXPECT_TRUE(same_file(set.files[i].paths.scene, entries[i].scene));
    EXPECT_TRUE(same_file(set.files[i].paths.observations, entries[i].observations));
    EXPECT_EQ(scene.mesh.num_vertices(), expected.scene.mesh.num_vertices());
    EXPECT_EQ(scene.mesh.rest_positions(), expected.scene.mesh.rest_positions());
    EXPECT_EQ(scene.frames, expected.scene.frames);
    EXPECT_EQ(scene.dt, expected.scene.dt);
    EXPECT_EQ(scene.fixed_vertices, expected.scene.fixed_vertices);
    EXPECT_EQ(set.files[i].scene_file.nominal_material, expected.nominal_material);
    expect_same_observation(set.motions[i].observed, read_observation_h5(entries[i].observations));
    EXPECT_TRUE(has_input(set, entries[i].scene));
    EXPECT_TRUE(has_input(set, entries[i].observations));
  }
  // The two motions really are different (mesh and length), and share the nominal material.
  EXPECT_NE(set.motions[0].scene.mesh.num_vertices(), set.motions[1].scene.mesh.num_vertices());
  EXPECT_NE(set.motions[0].observed.num_frames(), set.motions[1].observed.num_frames());
  EXPECT_EQ(set.nominal_material, read_scene_file(entries[0].scene).nominal_material);
  EXPECT_TRUE(has_input(set, dir / "set.json"));

  // Written again from what was read, the document is the same.
  std::vector<TrainingSetEntry> again;
  for (const TrainingSetFiles& f : set.files)
    again.push_back(f.paths);
  write_training_set(dir / "again.json", again);
  EXPECT_EQ(read_json_file(dir / "again.json"), written);
}

TEST(TrainingSet, ResolvesPathsAgainstItsOwnFolderFromAnyWorkingFolder) {
  const ScratchDir dir;
  two_motions(dir);
  // A set in a sibling folder, written by hand with paths relative to it.
  write_json(dir / "sets/set.json",
      set_json({ { "../a.json", "../a.h5" }, { "../motions/b.json", "../motions/b.h5" } }));
  for (const auto& cwd : { dir.path(), dir / "motions", dir / "elsewhere" }) {
    const WorkingFolder in(cwd);
    const std::filesystem::path set_path
        = std::filesystem::relative(dir / "sets/set.json", std::filesystem::current_path());
    ASSERT_TRUE(set_path.is_relative());
    const TrainingSet set = read_training_set(set_path);
    ASSERT_EQ(set.motions.size(), 2u) << cwd;
    EXPECT_TRUE(same_file(set.files[1].paths.scene, dir / "motions/b.json")) << cwd;
    EXPECT_TRUE(same_file(set.files[0].paths.observations, dir / "a.h5")) << cwd;
    EXPECT_EQ(set.motions[1].observed.num_frames(), 8) << cwd;
  }
  // Written from another working folder with paths relative to it: stored relative to the set.
  {
    const WorkingFolder in(dir / "motions");
    write_training_set(
        "../sets/written.json", { { "../a.json", "../a.h5" }, { "b.json", "b.h5" } });
  }
  const Json written = read_json_file(dir / "sets/written.json");
  EXPECT_EQ(written["motions"][0]["scene"], "../a.json");
  EXPECT_EQ(written["motions"][1]["observations"], "../motions/b.h5");
  const WorkingFolder in(dir / "elsewhere");
  EXPECT_EQ(read_training_set(dir / "sets/written.json").motions.size(), 2u);
  // Absolute paths are taken as they are.
  write_json(dir / "sets/absolute.json",
      set_json({ { (dir / "a.json").string(), (dir / "a.h5").string() } }));
  EXPECT_EQ(read_training_set(dir / "sets/absolute.json").motions.size(), 1u);
}

TEST(TrainingSet, ReadsOneSceneAndObservationPairWithTheSameChecks) {
  const ScratchDir dir;
  const auto entries = two_motions(dir);
  const TrainingSet one = read_training_motion({ entries[1].scene, entries[1].observations });
  ASSERT_EQ(one.motions.size(), 1u);
  EXPECT_TRUE(one.path.empty());
  EXPECT_EQ(one.motions[0].scene.frames, 7);
  EXPECT_TRUE(has_input(one, entries[1].observations));
  // a.h5 has 6 frames, b.json needs 8.
  expect_input_error(
      [&] {
        read_training_motion({ entries[1].scene, entries[0].observations });
      },
      { "a.h5", "frames" });
}

TEST(TrainingSet, RefusesMalformedSetsNamingFileAndField) {
  const ScratchDir dir;
  two_motions(dir);
  const auto set_path = dir / "set.json";
  const auto refused = [&](const Json& json, const std::vector<std::string>& parts) {
    write_json(set_path, json);
    SCOPED_TRACE(json.dump());
    const std::string message = expect_input_error([&] { read_training_set(set_path); }, parts);
    EXPECT_NE(message.find(set_path.string()), std::string::npos) << message;
  };
  const Json good = set_json({ { "a.json", "a.h5" }, { "motions/b.json", "motions/b.h5" } });
  write_json(set_path, good);
  EXPECT_EQ(read_training_set(set_path).motions.size(), 2u);

  Json j = good;
  j.erase("format");
  refused(j, { "format", "missing" });
  j = good;
  j["format"] = "elastolearn-scene/1";
  refused(j, { "format", "elastolearn-training/1" });
  j["format"] = "elastolearn-training/2";
  refused(j, { "format", "newer" });
  j = good;
  j.erase("motions");
  refused(j, { "motions", "missing" });
  j["motions"] = Json::object();
  refused(j, { "motions", "array" });
  j["motions"] = Json::array();
  refused(j, { "motions", "at least one motion" });
  j = good;
  j["motions"][1] = "b.json";
  refused(j, { "motions[1]" });
  j = good;
  j["motions"][1].erase("scene");
  refused(j, { "motions[1].scene", "missing" });
  j = good;
  j["motions"][0].erase("observations");
  refused(j, { "motions[0].observations", "missing" });
  j = good;
  j["motions"][0]["scene"] = "";
  refused(j, { "motions[0].scene", "empty" });
  j = good;
  j["motions"][0]["scene"] = 3;
  refused(j, { "motions[0].scene", "string" });
  j = good;
  j["motions"][1]["weight"] = 2;
  refused(j, { "motions[1]", "weight" });
  j = good;
  j["motoins"] = Json::array();
  refused(j, { "motoins" });

  // Observations that do not fit their scene: a.h5 has 6 frames, b.json needs 8; and b.h5's
  // vertex ids run past a.json's mesh.
  refused(set_json({ { "a.json", "a.h5" }, { "motions/b.json", "a.h5" } }),
      { "motions[1].observations", "a.h5", "frames" });
  write_json(dir / "c.json", scene_json(4, 7));
  refused(set_json({ { "c.json", "motions/b.h5" } }),
      { "motions[0].observations", "b.h5", "vertex id", "out of range" });
  // Another dt.
  Json other_dt = scene_json(4, 5);
  other_dt["time"]["dt"] = 0.02;
  write_json(dir / "dt.json", other_dt);
  refused(set_json({ { "dt.json", "a.h5" } }), { "motions[0].observations", "dt" });

  // Another nominal material than the first motion's.
  Json stiffer = scene_json(6, 7);
  stiffer["material"]["young"] = 2e5;
  write_json(dir / "stiffer.json", stiffer);
  refused(set_json({ { "a.json", "a.h5" }, { "stiffer.json", "motions/b.h5" } }),
      { "motions[1].scene", "stiffer.json", "material", "differs" });

  // Consistent mass.
  Json consistent = scene_json(4, 5);
  consistent["mass"] = "consistent";
  write_json(dir / "consistent.json", consistent);
  refused(set_json({ { "consistent.json", "a.h5" } }), { "motions[0].scene", "lumped" });

  // A material that already carries a correction (a learned-material file).
  MaterialFile learned;
  learned.material = scene_json(4, 5)["material"];
  material::RbfCorrection::Parameters p;
  p.centres.resize(0, 3);
  p.own_slope = -1e3;
  learned.correction = std::make_shared<material::RbfCorrection>(p);
  write_material_file(dir / "learned.json", learned);
  Json corrected = scene_json(4, 5);
  corrected["material"] = "learned.json";
  write_json(dir / "corrected.json", corrected);
  refused(set_json({ { "corrected.json", "a.h5" } }), { "motions[0].scene", "correction" });

  // A file that is missing: the reader's error names it.
  write_json(set_path, set_json({ { "a.json", "missing.h5" } }));
  expect_input_error([&] { read_training_set(set_path); }, { "missing.h5" });
}

TEST(TrainingSet, TellsATrainingSetFromOtherFiles) {
  const ScratchDir dir;
  const auto entries = two_motions(dir);
  write_training_set(dir / "set.json", entries);
  EXPECT_TRUE(is_training_set_file(dir / "set.json"));
  EXPECT_FALSE(is_training_set_file(dir / "a.json"));
  EXPECT_FALSE(is_training_set_file(dir / "a.h5"));
  EXPECT_FALSE(is_training_set_file(dir / "nothing.json"));
  expect_input_error([&] { write_training_set(dir / "empty.json", {}); }, { "empty.json" });
  expect_input_error(
      [&] {
        write_training_set(dir / "empty.json", { { "a.json", "" } });
      },
      { "empty.json" });
}

TEST(TrainingSet, AMotionMayBePointClouds) {
  const ScratchDir dir;
  const auto entries = two_motions(dir);
  // Clouds of a.json's 6 frames: one point each, the scanner's accuracy recorded.
  std::vector<capture::CloudFrame> frames(6);
  for (auto& f : frames)
    f.points = Positions::Zero(1, 3);
  const auto clouds = capture::PointCloudSequence::from_frames(frames, 0.01, 0, "clouds");
  write_clouds_h5(dir / "a_clouds.h5", clouds, { { "noise_sigma", "0.002" } });
  TrainingSetEntry cloud_motion;
  cloud_motion.scene = dir / "a.json";
  cloud_motion.clouds = dir / "a_clouds.h5";
  write_training_set(dir / "set.json", { cloud_motion, entries[1] });
  const Json written = read_json_file(dir / "set.json");
  EXPECT_EQ(written["motions"][0], Json({ { "scene", "a.json" }, { "clouds", "a_clouds.h5" } }));

  const TrainingSet set = read_training_set(dir / "set.json");
  ASSERT_EQ(set.motions.size(), 2u);
  ASSERT_NE(set.motions[0].captured, nullptr);
  EXPECT_EQ(set.motions[0].captured->clouds.num_frames(), 6);
  EXPECT_EQ(set.motions[0].captured->sigma, 0.002);
  EXPECT_EQ(set.motions[0].observed.num_frames(), 0) << "derived when learning";
  EXPECT_TRUE(same_file(set.files[0].paths.clouds, dir / "a_clouds.h5"));
  EXPECT_TRUE(has_input(set, dir / "a_clouds.h5"));
  EXPECT_EQ(set.motions[1].captured, nullptr);
  const TrainingSet one = read_training_motion(cloud_motion);
  EXPECT_NE(one.motions[0].captured, nullptr);

  // Both kinds of data in one motion, and clouds that do not fit the scene, are refused.
  const auto refused = [&](const Json& j, const std::vector<std::string>& words) {
    write_json(dir / "bad.json", j);
    expect_input_error([&] { read_training_set(dir / "bad.json"); }, words);
  };
  Json both = written;
  both["motions"][0]["observations"] = "a.h5";
  refused(both, { "motions[0].clouds", "not both" });
  Json other = written;
  other["motions"][0]["scene"] = "motions/b.json"; // 8 frames
  refused(other, { "motions[0].clouds", "a_clouds.h5", "has 6 frames, the scene 8" });
  expect_input_error(
      [&] {
        read_learning_data(
            dir / "a.json", dir / "a.h5", "--observations", dir / "a_clouds.h5", "--clouds");
      },
      { "--clouds", "not with --observations" });
}
