// `elastolearn learn` end to end through files: simulate a truth, observe a third of its surface,
// learn from a wrong nominal, evaluate on the training scene; bad observations are refused.
#include <support/cli_runner.hpp>

#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/learn/learning_recipe.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <unistd.h>

namespace fs = std::filesystem;
using elastolearn::test::run;

namespace {

/// The nominal scene: a corotated bar 1.75× too stiff (240 tets, 50 frames of 4 ms).
const char* k_scene = R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.4, 0.1, 0.1], "cells": [10, 2, 2]},
  "material": {"model": "corotated", "young": 1.75e6, "poisson": 0.43, "density": 1000,
               "damping": {"alpha0": 0.0, "alpha1": 0.01}},
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 4e-3, "frames": 50}
})";

const char* k_truth = R"({"format": "elastolearn-material/1", "correction": null,
  "material": {"model": "neohookean", "young": 1e6, "poisson": 0.43, "density": 1000,
               "damping": {"alpha0": 0.0, "alpha1": 0.01}}})";

class CliLearnTest : public elastolearn::test::CliTestFolder {
  protected:
  void SetUp() override {
    CliTestFolder::SetUp();
    write("scene.json", k_scene);
    write("truth.json", k_truth);
  }
  std::string path(const std::string& name) const { return (m_dir / name).string(); }

  /// `evaluate SCENE --material MATERIAL --truth TRUTH -q` on files of the test folder.
  struct Evaluation {
    elastolearn::test::Run result;
    double nominal = -1, learned = -1; ///< err_L [%] as printed (−1: not found)
  };
  Evaluation evaluate(
      const std::string& scene, const std::string& material, const std::string& truth) const;
};

double number_after(const std::string& text, const std::string& label) {
  std::smatch m;
  const std::regex re(label + R"(\s+([0-9.eE+-]+))");
  if (!std::regex_search(text, m, re))
    return -1;
  return std::stod(m[1]);
}

CliLearnTest::Evaluation CliLearnTest::evaluate(
    const std::string& scene, const std::string& material, const std::string& truth) const {
  Evaluation e;
  e.result = run("evaluate " + path(scene) + " --material " + path(material) + " --truth "
      + path(truth) + " -q");
  e.nominal = number_after(e.result.output, "nominal");
  e.learned = number_after(e.result.output, "learned");
  return e;
}

TEST_F(CliLearnTest, LearnsAndEvaluates) {
  ASSERT_EQ(run("simulate " + path("scene.json") + " --material " + path("truth.json") + " -o "
                + path("truth.h5") + " -q")
                .exit_code,
      0);
  ASSERT_EQ(
      run("observe " + path("truth.h5") + " --visible-fraction 0.3 -o " + path("obs.h5")).exit_code,
      0);
  const auto learned = run("learn " + path("scene.json") + " --observations " + path("obs.h5")
      + " -o " + path("learned.json")
      + " --max-iterations 3 --kernels 15 --modes 10 --forward-fit 3 --network-samples 4000 "
        "--report "
      + path("report") + " -q");
  ASSERT_EQ(learned.exit_code, 0) << learned.output;
  EXPECT_NE(learned.output.find("learned material:"), std::string::npos) << learned.output;
  EXPECT_TRUE(fs::exists(path("report/convergence.csv")));
  EXPECT_TRUE(fs::exists(path("learned.json.checkpoint.json")));
  const auto file = elastolearn::io::read_material_file(path("learned.json"));
  ASSERT_NE(file.correction, nullptr) << "a correction beat the nominal model";
  // At most iterations 0–3 of the loop (patience may end it sooner), then three forward-fit
  // steps (fewer than the recipe's eight: on these exact data the deeper fit reaches a teacher
  // that the small network reproduces only to a few per cent of its sub-micrometre error).
  int loop_records = 0, forward_fit_records = 0;
  for (const auto& r : file.training.at("history"))
    ++(r.at("kind") == "forward_fit" ? forward_fit_records : loop_records);
  EXPECT_GE(loop_records, 2);
  EXPECT_LE(loop_records, 4);
  EXPECT_EQ(forward_fit_records, 3);
  // The recipe's record: the candidates' validation errors, and the chosen one the lowest.
  const auto& recipe = file.training.at("recipe");
  const auto& candidates = recipe.at("candidates");
  ASSERT_GE(candidates.size(), 3u) << recipe.dump(); // nominal, fitted nominal, corrections
  EXPECT_EQ(candidates.at(1).at("kind"), "fitted nominal");
  const auto chosen = recipe.at("chosen").get<size_t>();
  // The network of the chosen RBF is the last candidate; on these exact data it reproduces its
  // teacher and replaces it (within kNetworkTolerance of its validation error).
  const auto& network = candidates.back();
  ASSERT_EQ(network.at("kind"), "network") << recipe.dump();
  ASSERT_EQ(chosen, candidates.size() - 1) << recipe.dump();
  const auto teacher = network.at("teacher").get<size_t>();
  EXPECT_EQ(candidates.at(teacher).at("iteration"), network.at("iteration"));
  for (const auto& c : candidates) {
    if (c.at("completed").get<bool>()) {
      EXPECT_LE(candidates.at(chosen).at("validation_rms_error_m").get<double>(),
          (1 + elastolearn::learn::kNetworkTolerance)
              * c.at("validation_rms_error_m").get<double>());
    }
  }
  EXPECT_TRUE(file.training.at("network").at("chosen").get<bool>());
  EXPECT_NE(learned.output.find("<- chosen"), std::string::npos) << learned.output;
  ASSERT_TRUE(file.training_stretches.has_value())
      << "learn records the training motion's stretches";
  EXPECT_GT(file.training_stretches->max[0], 1.0) << "the droop stretches the bar";
  EXPECT_LT(file.training_stretches->min[2], 1.0) << "and compresses it";
  const auto described = run("info " + path("learned.json"));
  ASSERT_EQ(described.exit_code, 0) << described.output;
  EXPECT_NE(described.output.find("correction (nn (energy"), std::string::npos) << described.output;
  // The RBF it was distilled from is kept in the file.
  const auto rbf = elastolearn::io::correction_from_json(
      elastolearn::io::JsonObject(file.training.at("teacher"), "learned.json", "training.teacher"));
  EXPECT_NE(elastolearn::io::describe_correction(*rbf).find("rbf, 15 centres"), std::string::npos)
      << elastolearn::io::describe_correction(*rbf);
  EXPECT_NE(described.output.find("training stretches: s₁ 1.0"), std::string::npos)
      << described.output;

  const auto e = evaluate("scene.json", "learned.json", "truth.h5");
  const auto& evaluated = e.result;
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  ASSERT_GT(e.nominal, 0) << evaluated.output;
  ASSERT_GE(e.learned, 0) << evaluated.output;
  EXPECT_LT(e.learned, e.nominal / 5) << evaluated.output;
  // Evaluated on its own training motion, the learned model stays inside its training stretches.
  EXPECT_NE(evaluated.output.find("stretches:"), std::string::npos) << evaluated.output;
  EXPECT_EQ(evaluated.output.find("note:"), std::string::npos) << evaluated.output;

  // A training range narrowed to half the stretches: evaluate and simulate say where the motion
  // leaves it, and the evaluation report counts the samples outside.
  auto narrow = file;
  narrow.training_stretches->max[0] = 1.0 + 0.5 * (file.training_stretches->max[0] - 1.0);
  elastolearn::io::write_material_file(path("narrow.json"), narrow);
  const auto noted = run("evaluate " + path("scene.json") + " --material " + path("narrow.json")
      + " --truth " + path("truth.h5") + " --json " + path("evaluation.json") + " -q");
  ASSERT_EQ(noted.exit_code, 0) << noted.output;
  EXPECT_NE(noted.output.find("note:"), std::string::npos) << noted.output;
  EXPECT_NE(noted.output.find("s₁ up to"), std::string::npos) << noted.output;
  const auto report = elastolearn::io::read_json_file(path("evaluation.json"));
  const double outside = report.at("stretches").at("fraction_outside").get<double>();
  EXPECT_GT(outside, 0.0);
  EXPECT_LT(outside, 1.0);
  const auto simulated = run("simulate " + path("scene.json") + " --material " + path("narrow.json")
      + " -o " + path("narrow.h5") + " -q");
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  EXPECT_NE(simulated.output.find("note:"), std::string::npos) << simulated.output;

  // --resume of a finished run changes nothing and says where it resumed.
  const auto resumed = run("learn " + path("scene.json") + " --observations " + path("obs.h5")
      + " -o " + path("learned2.json") + " --checkpoint " + path("learned.json.checkpoint.json")
      + " --max-iterations 3 --kernels 15 --modes 10 --forward-fit 3 --network-samples 4000 "
        "--resume -q");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resuming"), std::string::npos);
  const auto again = elastolearn::io::read_material_file(path("learned2.json"));
  EXPECT_EQ(elastolearn::io::correction_to_json(*again.correction),
      elastolearn::io::correction_to_json(*file.correction));
}

TEST_F(CliLearnTest, LearnsOneCorrectionFromATrainingSetOfSeveralMotions) {
  // Three motions of the bar (a droop and two swings), learned from together; each one's last
  // 20 % of frames is held out for validation; paths in the set are relative to its folder.
  const std::string swing_up = std::regex_replace(k_scene, std::regex(R"("fixed")"),
      R"("initial": {"type": "velocity", "angular_velocity": [0, 0, 2.0]}, "fixed")");
  const std::string swing_down = std::regex_replace(swing_up, std::regex("2\\.0\\]"), "-1.5]");
  write("up.json", swing_up);
  write("down.json", swing_down);
  for (const std::string name : { "scene", "up", "down" }) {
    ASSERT_EQ(run("simulate " + path(name + ".json") + " --material " + path("truth.json") + " -o "
                  + path(name + "_truth.h5") + " -q")
                  .exit_code,
        0);
    ASSERT_EQ(run("observe " + path(name + "_truth.h5") + " --visible-fraction 0.3 -o "
                  + path(name + "_obs.h5"))
                  .exit_code,
        0);
  }
  fs::create_directories(m_dir / "sets");
  write("sets/three.json", R"({"format": "elastolearn-training/1", "motions": [
    {"scene": "../scene.json", "observations": "../scene_obs.h5"},
    {"scene": "../up.json", "observations": "../up_obs.h5"},
    {"scene": "../down.json", "observations": "../down_obs.h5"}]})");
  const auto learned = run("learn " + path("sets/three.json") + " -o " + path("set.json")
      + " --max-iterations 2 --kernels 15 --modes 10 --no-network -q");
  ASSERT_EQ(learned.exit_code, 0) << learned.output;
  EXPECT_NE(learned.output.find("validation on the last 20 %"), std::string::npos)
      << learned.output;
  for (const std::string name : { "scene_obs.h5", "up_obs.h5", "down_obs.h5" })
    EXPECT_NE(learned.output.find(name), std::string::npos) << learned.output;
  EXPECT_EQ(learned.output.find("network"), std::string::npos) << "--no-network:\n"
                                                               << learned.output;
  const auto file = elastolearn::io::read_material_file(path("set.json"));
  EXPECT_EQ(file.training.at("motions").size(), 3u);
  // The learned material predicts the swing (down) better than the nominal.
  const auto e = evaluate("down.json", "set.json", "down_truth.h5");
  ASSERT_EQ(e.result.exit_code, 0) << e.result.output;
  ASSERT_GT(e.nominal, 0) << e.result.output;
  EXPECT_LT(e.learned, e.nominal / 5) << e.result.output;
}

TEST_F(CliLearnTest, LearnsFromPointCloudsAsFromObservations) {
  // Two depth cameras (front and above) scan the truth's droop with 1 mm of depth noise; learn
  // tracks the clouds with the nominal and again with the fitted nominal, then learns from the
  // tracked surface where the clouds see it. A training set mixing a cloud motion and an
  // observation motion learns the same way.
  write("cams.json", R"({"format": "elastolearn-cameras/1", "cameras": [
    {"name": "front", "position": [0.2, 0.0, 0.9], "look_at": [0.2, -0.02, 0.05], "up": [0, 1, 0],
     "resolution": [320, 240], "fov_y": 45},
    {"name": "top", "position": [0.25, 0.7, 0.4], "look_at": [0.2, -0.02, 0.05], "up": [0, 1, 0],
     "resolution": [320, 240], "fov_y": 45}]})");
  ASSERT_EQ(run("simulate " + path("scene.json") + " --material " + path("truth.json") + " -o "
                + path("truth.h5") + " -q")
                .exit_code,
      0);
  const auto scanned = run("scan " + path("truth.h5") + " --camera " + path("cams.json")
      + " --noise 0.001 --seed 2 -q -o " + path("clouds.h5"));
  ASSERT_EQ(scanned.exit_code, 0) << scanned.output;
  const auto learned = run("learn " + path("scene.json") + " --clouds " + path("clouds.h5") + " -o "
      + path("learned.json") + " --max-iterations 2 --kernels 15 --modes 10 --no-network -q");
  ASSERT_EQ(learned.exit_code, 0) << learned.output;
  EXPECT_NE(learned.output.find("clouds of " + path("clouds.h5") + " tracked with the given"),
      std::string::npos)
      << learned.output;
  EXPECT_NE(learned.output.find("tracked with the fitted nominal"), std::string::npos)
      << learned.output;
  const auto file = elastolearn::io::read_material_file(path("learned.json"));
  EXPECT_EQ(file.training.at("motions").at(0).at("clouds"), path("clouds.h5"));
  // The clouds see the front and top of the bar, not its back and bottom: fewer vertices than
  // the surface's 168, more than a third of them.
  const int observed = file.training.at("observed_vertices").get<int>();
  EXPECT_GT(observed, 56);
  EXPECT_LE(observed, 168);
  const auto e = evaluate("scene.json", "learned.json", "truth.h5");
  ASSERT_EQ(e.result.exit_code, 0) << e.result.output;
  ASSERT_GT(e.nominal, 0) << e.result.output;
  std::printf("err_L on the training motion: nominal %g %%, learned from clouds %g %%\n", e.nominal,
      e.learned);
  // Measured: nominal 3.18 %, learned from the clouds 0.059 %; learning that ignored the clouds
  // could not pass.
  EXPECT_LT(e.learned, e.nominal / 5) << e.result.output;

  ASSERT_EQ(
      run("observe " + path("truth.h5") + " --visible-fraction 0.3 -o " + path("obs.h5")).exit_code,
      0);
  write("set.json", R"({"format": "elastolearn-training/1", "motions": [
    {"scene": "scene.json", "clouds": "clouds.h5"},
    {"scene": "scene.json", "observations": "obs.h5"}]})");
  const auto mixed = run("learn " + path("set.json") + " -o " + path("mixed.json")
      + " --max-iterations 1 --kernels 15 --modes 10 --no-network -q");
  ASSERT_EQ(mixed.exit_code, 0) << mixed.output;
  // Both motions validate, the cloud one on its tracked observations.
  for (const std::string name : { "clouds.h5", "obs.h5" })
    EXPECT_NE(mixed.output.find("10 of 50 frames of " + path(name)), std::string::npos)
        << mixed.output;

  // Both kinds of data for one scene is one error, and nothing is written.
  const auto both = run("learn " + path("scene.json") + " --clouds " + path("clouds.h5")
      + " --observations " + path("obs.h5") + " -o " + path("both.json"));
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_NE(both.output.find("--clouds: not with --observations"), std::string::npos)
      << both.output;
  EXPECT_FALSE(fs::exists(path("both.json")));
}

TEST_F(CliLearnTest, RefusesObservationsOfAnotherLength) {
  std::ofstream(m_dir / "short.json")
      << std::regex_replace(k_scene, std::regex("\"frames\": 50"), "\"frames\": 20");
  ASSERT_EQ(run("simulate " + path("short.json") + " -o " + path("short.h5") + " -q").exit_code, 0);
  ASSERT_EQ(
      run("observe " + path("short.h5") + " --visible-fraction 0.3 -o " + path("obs.h5")).exit_code,
      0);
  const auto r = run("learn " + path("scene.json") + " --observations " + path("obs.h5") + " -o "
      + path("l.json"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("obs.h5"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frames"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("l.json")));
}

TEST_F(CliLearnTest, RefusesAConsistentMassSceneNamingTheField) {
  ASSERT_EQ(run("simulate " + path("scene.json") + " -o " + path("truth.h5") + " -q").exit_code, 0);
  ASSERT_EQ(
      run("observe " + path("truth.h5") + " --visible-fraction 0.3 -o " + path("obs.h5")).exit_code,
      0);
  std::ofstream(m_dir / "consistent.json") << std::regex_replace(
      k_scene, std::regex("\"gravity\""), "\"mass\": \"consistent\", \"gravity\"");
  const auto r = run("learn " + path("consistent.json") + " --observations " + path("obs.h5")
      + " -o " + path("l.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(
      r.output.find("consistent.json: mass: learning needs \"lumped\" mass"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(path("l.json")));
}

} // namespace
