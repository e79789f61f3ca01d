// End-to-end tests of learned-material files in the CLI: `simulate --material`, scenes that
// reference a material file, and `evaluate` (err_L of nominal and learned vs a true trajectory).
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <support/cli_runner.hpp>

#include <gtest/gtest.h>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace elastolearn;

namespace {

using elastolearn::test::Run;
using elastolearn::test::run;

/// The truth: a neo-Hookean bar sagging under gravity (192 tets, 20 frames).
const char* k_truth_scene = R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [8, 2, 2]},
  "material": {"model": "neohookean", "young": 1e5, "poisson": 0.4, "density": 1000,
               "damping": {"alpha0": 0.1, "alpha1": 0.001}},
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 0.01, "frames": 20}
})";

const char* k_truth_material
    = R"({"model": "neohookean", "young": 1e5, "poisson": 0.4, "density": 1000,
  "damping": {"alpha0": 0.1, "alpha1": 0.001}})";

class CliEvaluateTest : public elastolearn::test::CliTestFolder {
  protected:
  /// The truth scene with its material replaced by `material` (JSON text of the "material" value).
  fs::path scene_with_material(const std::string& name, const std::string& material) {
    std::string text = k_truth_scene;
    const auto begin = text.find("\"material\"");
    const auto end = text.find("\"gravity\"");
    text.replace(begin, end - begin, "\"material\": " + material + ",\n  ");
    return write(name, text);
  }
  /// Simulate the truth scene into truth.h5 (with `extra` arguments).
  fs::path simulate_truth(const std::string& extra = "") {
    const auto out = m_dir / "truth.h5";
    const auto r = run("simulate " + write("truth.json", k_truth_scene).string() + " -o "
        + out.string() + " -q " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return out;
  }
};

const char* k_nominal_material
    = R"({"model": "corotated", "young": 1.5e5, "poisson": 0.4, "density": 1000,
  "damping": {"alpha0": 0.1, "alpha1": 0.001}})";

} // namespace

TEST_F(CliEvaluateTest, LearnedMaterialEqualToTheTruthHasZeroErrorAndTheNominalDoesNot) {
  const auto truth = simulate_truth();
  const auto test_scene = scene_with_material("test.json", k_nominal_material);
  const auto learned = write("learned.json",
      std::string(R"({"format": "elastolearn-material/1", "material": )") + k_truth_material + "}");
  const auto report = m_dir / "report.json";
  const auto learned_traj = m_dir / "learned_traj.h5";
  const auto r
      = run("evaluate " + test_scene.string() + " --material " + learned.string() + " --truth "
          + truth.string() + " --json " + report.string() + " -o " + learned_traj.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("err_L"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("neohookean (" + learned.string() + ")"), std::string::npos) << r.output;

  const nlohmann::json j = io::read_json_file(report);
  // The learned run is the truth's own computation (same scene, material, solver, and
  // deterministic assembly), so its error is zero up to round-off; 1e-9 % of the size is far
  // below any modelling error.
  EXPECT_LT(j["learned"]["err_L_percent"].get<double>(), 1e-9) << j.dump(2);
  // 1.5× too stiff and corotated instead of neo-Hookean: the sag differs by well over 1 %.
  EXPECT_GT(j["nominal"]["err_L_percent"].get<double>(), 1.0) << j.dump(2);
  EXPECT_GT(
      j["nominal"]["err_L_percent"].get<double>(), j["nominal"]["mean_percent"].get<double>());
  EXPECT_EQ(j["frames"], 21);
  EXPECT_EQ(j["nominal"]["frames_compared"], 21);
  EXPECT_NEAR(j["size"].get<double>(), std::sqrt(0.2 * 0.2 + 2 * 0.05 * 0.05), 1e-12);

  const auto t = io::read_trajectory_h5(truth);
  const auto l = io::read_trajectory_h5(learned_traj);
  ASSERT_EQ(l.positions.size(), t.positions.size());
  EXPECT_LT((l.positions.back() - t.positions.back()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST_F(CliEvaluateTest, SimulateTakesTheLearnedMaterialFromTheOptionOrTheScene) {
  // A material file with a (made-up, modest) RBF correction: stiffer in tension.
  material::RbfCorrection::Parameters p;
  p.centres.resize(2, 3);
  p.centres << 1.05, 1.0, 1.0, 0.95, 1.0, 1.0;
  p.weights.resize(2);
  p.weights << 2e3, -2e3;
  p.own_slope = 3e4;
  io::MaterialFile file;
  file.material = nlohmann::json::parse(k_truth_material);
  file.correction = std::make_shared<material::RbfCorrection>(p);
  io::write_material_file(m_dir / "learned.json", file);

  const auto plain = simulate_truth();
  const auto scene = write("truth.json", k_truth_scene);
  const auto by_option = m_dir / "option.h5";
  auto r = run("simulate " + scene.string() + " --material " + (m_dir / "learned.json").string()
      + " -o " + by_option.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("correction (rbf, 2 centres)"), std::string::npos) << r.output;

  const auto by_scene = m_dir / "scene.h5";
  r = run("simulate " + scene_with_material("ref.json", "\"learned.json\"").string() + " -o "
      + by_scene.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const auto a = io::read_trajectory_h5(by_option), b = io::read_trajectory_h5(by_scene),
             c = io::read_trajectory_h5(plain);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(a.positions.back(), b.positions.back()); // the same model either way
  // The correction stiffens the bar: it must change the motion (by far more than round-off).
  EXPECT_GT((a.positions.back() - c.positions.back()).cwiseAbs().maxCoeff(), 1e-5);
}

TEST_F(CliEvaluateTest, BadTruthFileIsNamedAndNothingIsWritten) {
  const auto test_scene = scene_with_material("test.json", k_nominal_material);
  const auto learned = write("learned.json",
      std::string(R"({"format": "elastolearn-material/1", "material": )") + k_truth_material + "}");
  const auto report = m_dir / "report.json";
  const std::string common = "evaluate " + test_scene.string() + " --material " + learned.string()
      + " --json " + report.string() + " -q --truth ";

  auto r = run(common + (m_dir / "missing.h5").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("missing.h5"), std::string::npos) << r.output;

  const auto garbage = write("garbage.h5", "not hdf5");
  r = run(common + garbage.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("garbage.h5"), std::string::npos) << r.output;

  const auto short_truth = simulate_truth("--frames 10");
  r = run(common + short_truth.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("truth.h5: /positions"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("11 frames"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(report));
}
