// End-to-end tests of the `elastolearn` executable: what a user sees.
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <support/cli_runner.hpp>

#include <gtest/gtest.h>
#include <string>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace {

using elastolearn::test::Run;
using elastolearn::test::run;

using CliTest = elastolearn::test::CliTestFolder;

const char* kSmallScene = R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [4, 1, 1]},
  "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000,
               "damping": {"alpha0": 0.1, "alpha1": 0.001}},
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 0.002, "frames": 20}
})";

} // namespace

TEST_F(CliTest, SimulateWritesATrajectoryAndAParaViewSeries) {
  const auto scene = write("bar.json", kSmallScene);
  const auto out = m_dir / "bar.h5";
  const auto r = run("simulate " + scene.string() + " -o " + out.string() + " --vtu "
      + (m_dir / "vtu").string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto t = elastolearn::io::read_trajectory_h5(out);
  EXPECT_EQ(t.positions.size(), 21u);
  EXPECT_NEAR(t.time.back(), 0.04, 1e-12);
  EXPECT_LT(t.positions.back().col(1).minCoeff(), -1e-4); // it sags
  EXPECT_TRUE(fs::exists(m_dir / "vtu" / "bar.pvd"));
  EXPECT_NE(r.output.find("bar.h5"), std::string::npos);
}

TEST_F(CliTest, BadSceneGivesOneLineNamingTheFieldAndNoOutput) {
  std::string text = kSmallScene;
  text.replace(text.find("\"young\": 1e5"), 12, "\"young\": -3");
  const auto scene = write("bad.json", text);
  const auto r = run("simulate " + scene.string() + " -o " + (m_dir / "x.h5").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("material.young"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_FALSE(fs::exists(m_dir / "x.h5"));
}

TEST_F(CliTest, UnknownKeyAndBrokenJsonAreReportedWithTheirPlace) {
  std::string typo = kSmallScene;
  typo.replace(typo.find("\"poisson\""), 9, "\"poison\"");
  auto r
      = run("simulate " + write("typo.json", typo).string() + " -o " + (m_dir / "x.h5").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("poison"), std::string::npos) << r.output;
  r = run("simulate " + write("broken.json", "{\"format\": ").string() + " -o "
      + (m_dir / "x.h5").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("broken.json"), std::string::npos) << r.output;
}

TEST_F(CliTest, DivergenceNamesTheFrameAndKeepsEarlierFrames) {
  // One Newton iteration per attempt to 1e-12, no substeps, cannot converge once the bar moves:
  // the run must stop, say at which frame, exit non-zero, and keep the frames before it in a
  // readable file.
  std::string text = kSmallScene;
  text.replace(text.find("\"time\""), 6,
      "\"solver\": {\"max_newton_iterations\": 1, \"newton_tolerance\": 1e-12, "
      "\"max_step_halvings\": 0}, \"time\"");
  const auto out = m_dir / "div.h5";
  const auto r
      = run("simulate " + write("div.json", text).string() + " -o " + out.string() + " -q");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("diverged at frame"), std::string::npos) << r.output;
  const auto t = elastolearn::io::read_trajectory_h5(out);
  EXPECT_GE(t.positions.size(), 1u);
  EXPECT_NE(t.metadata.at("status").find("diverged at frame"), std::string::npos);
}

TEST_F(CliTest, InfoDescribesMeshesTrajectoriesAndScenes) {
  const auto scene = write("bar.json", kSmallScene);
  ASSERT_EQ(
      run("simulate " + scene.string() + " -o " + (m_dir / "bar.h5").string() + " -q").exit_code,
      0);
  const auto r = run("info " + scene.string() + " " + (m_dir / "bar.h5").string() + " "
      + std::string(ELASTOLEARN_EXAMPLES_DIR) + "/03_real_mesh/elephant.node");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("21 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("2830 tets"), std::string::npos) << r.output;
  EXPECT_EQ(run("info " + (m_dir / "missing.node").string()).exit_code, 2);
}

namespace {

/// The example files of one format ("scene" or "material"), as paths relative to examples/:
/// every JSON file under examples/ whose "format" is elastolearn-<kind>/1.
std::set<std::string> example_files(const std::string& kind) {
  const std::regex format("\"format\"\\s*:\\s*\"elastolearn-" + kind + "/1\"");
  const fs::path root(ELASTOLEARN_EXAMPLES_DIR);
  std::set<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.path().extension() != ".json")
      continue;
    std::ifstream in(entry.path());
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (std::regex_search(text, format))
      files.insert(fs::relative(entry.path(), root).string());
  }
  return files;
}

} // namespace

// Every example scene and material file loads (meshes, selections, material fields), so an example
// cannot rot unnoticed; `info` builds the scene as `simulate` does.
TEST_F(CliTest, ExampleScenesAndMaterialsLoad) {
  const auto scenes = example_files("scene");
  const auto materials = example_files("material");
  for (const char* known : { "01_cantilever/cantilever.json", "02_sphere/sphere.json",
           "03_real_mesh/elephant.json", "04_learning/bar_train.json", "04_learning/bar_test.json",
           "08_transfer/ball_train.json", "08_transfer/elephant_test.json" })
    EXPECT_EQ(scenes.count(known), 1u) << known << " was not found as a scene";
  for (const char* known : { "04_learning/truth.json", "08_transfer/truth.json" })
    EXPECT_EQ(materials.count(known), 1u) << known << " was not found as a material";
  for (const auto& scene : scenes) {
    const auto r = run("info " + std::string(ELASTOLEARN_EXAMPLES_DIR) + "/" + scene);
    EXPECT_EQ(r.exit_code, 0) << scene << ": " << r.output;
    EXPECT_NE(r.output.find("scene '"), std::string::npos) << scene << ": " << r.output;
  }
  for (const auto& material : materials) {
    const auto r = run("info " + std::string(ELASTOLEARN_EXAMPLES_DIR) + "/" + material);
    EXPECT_EQ(r.exit_code, 0) << material << ": " << r.output;
    EXPECT_NE(r.output.find("learned material"), std::string::npos) << material << ": " << r.output;
  }
  // The transfer example drives the mesh of 03_real_mesh (referenced, not copied).
  const auto r
      = run("info " + std::string(ELASTOLEARN_EXAMPLES_DIR) + "/08_transfer/elephant_test.json");
  EXPECT_NE(r.output.find("2830 tets"), std::string::npos) << r.output;
}

// The example scripts are too slow for this suite (minutes of learning); their shell syntax is
// checked here, what they compute in their READMEs.
TEST_F(CliTest, ExampleScriptsHaveValidShellSyntax) {
  const fs::path root(ELASTOLEARN_EXAMPLES_DIR);
  std::set<std::string> scripts;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.path().extension() == ".sh")
      scripts.insert(entry.path().string());
  EXPECT_EQ(scripts.count((root / "08_transfer" / "run.sh").string()), 1u);
  for (const auto& script : scripts) {
    const int status = std::system(("bash -n '" + script + "' 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << script;
  }
}

TEST_F(CliTest, InterruptKeepsTheFramesSoFarAndLeavesNoTemporaryFile) {
  std::string text = kSmallScene;
  text.replace(text.find("\"frames\": 20"), 12, "\"frames\": 100000");
  const auto out = m_dir / "long.h5", log = m_dir / "long.log";
  // Interrupt only once the first progress line is out: it comes after frame 1 is written, so
  // frames 0 and 1 must survive. A fixed sleep instead failed on a loaded CI machine.
  const auto script = write("interrupt.sh",
      std::string(ELASTOLEARN_EXECUTABLE) + " simulate " + write("long.json", text).string()
          + " -o " + out.string() + " > " + log.string() + " 2>&1 & pid=$!\n"
          + "for i in $(seq 600); do grep -q 'simulate ' " + log.string()
          + " && break; sleep 0.1; done\nkill -INT $pid; wait $pid\n");
  const int status = std::system(("bash " + script.string()).c_str());
  EXPECT_NE(status, 0);
  const auto t = elastolearn::io::read_trajectory_h5(out);
  EXPECT_GE(t.positions.size(), 2u);
  EXPECT_NE(t.metadata.at("status").find("interrupted"), std::string::npos);
  for (const auto& entry : fs::directory_iterator(m_dir))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST_F(CliTest, ObserveSamplesSurfaceVerticesReproducibly) {
  const auto scene = write("bar.json", kSmallScene);
  const auto traj = m_dir / "bar.h5";
  ASSERT_EQ(run("simulate " + scene.string() + " -o " + traj.string() + " -q").exit_code, 0);
  const auto a = m_dir / "a.h5", b = m_dir / "b.h5";
  for (const auto& out : { a, b }) {
    const auto r = run("observe " + traj.string()
        + " --visible-fraction 0.3 --noise 1e-4 --seed 7 -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const auto oa = elastolearn::io::read_observation_h5(a),
             ob = elastolearn::io::read_observation_h5(b);
  EXPECT_EQ(oa.positions.size(), 21u);
  EXPECT_EQ(oa.vertex_ids, ob.vertex_ids);
  EXPECT_EQ((oa.positions.back() - ob.positions.back()).norm(), 0.0); // same seed, same noise
  EXPECT_NEAR(oa.dt, 0.002, 1e-12);
  // Ids outside the mesh are refused with the file named.
  std::ofstream(m_dir / "ids.txt") << "0\n99999\n";
  const auto r = run("observe " + traj.string() + " --vertices " + (m_dir / "ids.txt").string()
      + " -o " + (m_dir / "c.h5").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("ids.txt"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(m_dir / "c.h5"));
}

TEST_F(CliTest, ObserveDropoutLosesBurstsReproduciblyAndInfoCountsThem) {
  const auto scene = write("bar.json", kSmallScene);
  const auto traj = m_dir / "bar.h5";
  ASSERT_EQ(run("simulate " + scene.string() + " -o " + traj.string() + " -q").exit_code, 0);
  const auto plain = m_dir / "plain.h5", a = m_dir / "a.h5", b = m_dir / "b.h5";
  const std::string observe
      = "observe " + traj.string() + " --visible-fraction 1 --noise 1e-4 --seed 7";
  ASSERT_EQ(run(observe + " -o " + plain.string()).exit_code, 0);
  for (const auto& out : { a, b }) {
    const auto r = run(observe + " --dropout 0.3 --dropout-burst 3 -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("vertex-frames lost"), std::string::npos) << r.output;
  }
  const auto p = elastolearn::io::read_observation_h5(plain);
  const auto oa = elastolearn::io::read_observation_h5(a),
             ob = elastolearn::io::read_observation_h5(b);
  ASSERT_EQ(oa.valid.rows(), oa.num_frames());
  EXPECT_TRUE((oa.valid == ob.valid).all()) << "same seed, same bursts";
  EXPECT_EQ(p.valid.size(), 0);
  // Seen entries are the plain observation's (the dropout draws from its own stream, so the
  // noise is unchanged); lost ones are NaN.
  for (int t = 0; t < oa.num_frames(); ++t)
    for (int j = 0; j < oa.num_observed(); ++j) {
      if (oa.is_valid(t, j))
        EXPECT_EQ(oa.positions[t].row(j), p.positions[t].row(j));
      else
        EXPECT_TRUE(oa.positions[t].row(j).array().isNaN().all());
    }
  const long lost = long(oa.num_frames()) * oa.num_observed() - oa.num_valid();
  EXPECT_GT(lost, 0);
  const auto r = run("info " + a.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("/observed/valid: " + std::to_string(lost) + " of"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("dropout: 0.3"), std::string::npos) << r.output;
}

TEST_F(CliTest, InfoDescribesObservationFiles) {
  const auto traj = m_dir / "bar.h5", obs = m_dir / "obs.h5";
  ASSERT_EQ(
      run("simulate " + write("bar.json", kSmallScene).string() + " -o " + traj.string() + " -q")
          .exit_code,
      0);
  ASSERT_EQ(run("observe " + traj.string() + " --visible-fraction 0.5 --noise 1e-4 --seed 7 -o "
                + obs.string())
                .exit_code,
      0);
  const auto r = run("info " + obs.string() + " " + traj.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // What the file holds: frames and their times, the observed vertices, the noise it recorded.
  EXPECT_NE(
      r.output.find("observation: 21 frames, t = 0 .. 0.04 s (dt = 0.002 s)"), std::string::npos)
      << r.output;
  const auto observed = elastolearn::io::read_observation_h5(obs);
  EXPECT_NE(r.output.find(std::to_string(observed.num_observed()) + " observed vertices"),
      std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("noise_sigma: 1e-04"), std::string::npos)
      << r.output; // shortest exact text
  EXPECT_NE(r.output.find("source: " + traj.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("trajectory: 21 frames"), std::string::npos) << r.output; // still
}
