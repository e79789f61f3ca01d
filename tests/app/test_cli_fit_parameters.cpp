// End-to-end test of `elastolearn fit-parameters`: simulate a truth, observe it, fit the nominal
// parameters of a wrong start, and read the written material file back.
#include <elastolearn/io/material_file.hpp>

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

/// A corotated bar sagging and swinging under gravity (192 tets, 30 frames), with the material
/// left open.
std::string bar_scene(const std::string& material) {
  return R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [8, 2, 2]},
  "material": )"
      + material + R"(,
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 0.005, "frames": 30}
})";
}

class CliFitParametersTest : public elastolearn::test::CliTestFolder {
  protected:
  /// Simulate the truth (E = 1.5e5, α₁ = 3e-3) and observe half of its surface vertices.
  fs::path observe_truth() {
    const auto truth = write("truth.json",
        bar_scene(R"({"model": "corotated", "young": 1.5e5, "poisson": 0.3, "density": 1000,
                      "damping": {"alpha0": 0.2, "alpha1": 3e-3}})"));
    const auto traj = m_dir / "truth.h5", obs = m_dir / "obs.h5";
    const auto s = run("simulate " + truth.string() + " -o " + traj.string() + " -q");
    EXPECT_EQ(s.exit_code, 0) << s.output;
    const auto o = run("observe " + traj.string() + " --visible-fraction 0.5 -o " + obs.string());
    EXPECT_EQ(o.exit_code, 0) << o.output;
    return obs;
  }
};

const char* k_start_material
    = R"({"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000,
                                   "damping": {"alpha0": 0.2, "alpha1": 1e-3}})";

} // namespace

TEST_F(CliFitParametersTest, FitsYoungAndDampingAndWritesAMaterialFile) {
  const auto obs = observe_truth();
  const auto scene = write("start.json", bar_scene(k_start_material));
  const auto out = m_dir / "fitted.json";
  const auto r = run("fit-parameters " + scene.string() + " --observations " + obs.string() + " -o "
      + out.string() + " --fit young,alpha1 --max-iterations 15");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("iteration 1:"), std::string::npos) << r.output; // progress per iteration
  const io::MaterialFile fitted = io::read_material_file(out);
  // Noise-free data from the same model: the fit reaches the truth up to the finite-difference
  // and Newton-tolerance noise (far below 1 %, see tests/learn/test_parameter_fit.cpp).
  EXPECT_NEAR(fitted.material.at("young").get<double>() / 1.5e5, 1.0, 1e-2) << r.output;
  EXPECT_NEAR(fitted.material.at("damping").at("alpha1").get<double>() / 3e-3, 1.0, 2e-2)
      << r.output;
  EXPECT_EQ(fitted.material.at("damping").at("alpha0").get<double>(), 0.2); // not fitted
  EXPECT_EQ(fitted.material.at("poisson").get<double>(), 0.3);
  EXPECT_EQ(fitted.correction, nullptr);
  EXPECT_EQ(fitted.training.at("method"), "parameter_fit");
  EXPECT_LT(fitted.training.at("final_rms_error_m").get<double>(),
      1e-2 * fitted.training.at("initial_rms_error_m").get<double>());
  // The written file is a material `simulate` accepts.
  const auto check = write("check.json", bar_scene("\"" + out.filename().string() + "\""));
  const auto s = run("simulate " + check.string() + " -o " + (m_dir / "check.h5").string() + " -q");
  EXPECT_EQ(s.exit_code, 0) << s.output;
}

TEST_F(CliFitParametersTest, BadOptionsNameTheProblemAndWriteNothing) {
  const auto obs = observe_truth();
  const auto scene = write("start.json", bar_scene(k_start_material));
  const auto out = m_dir / "fitted.json";
  auto r = run("fit-parameters " + scene.string() + " --observations " + obs.string() + " -o "
      + out.string() + " --fit young,stiffness");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--fit"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("stiffness"), std::string::npos) << r.output;
  // An observation of a different motion length is refused with the file named.
  const auto longer = write("longer.json",
      bar_scene(k_start_material)
          .replace(bar_scene(k_start_material).find("\"frames\": 30"), 12, "\"frames\": 40"));
  r = run("fit-parameters " + longer.string() + " --observations " + obs.string() + " -o "
      + out.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("obs.h5"), std::string::npos) << r.output;
  // A stretch-dependent damping cannot be a start for constant coefficients.
  const auto splined
      = write("splined.json", bar_scene(R"({"model": "corotated", "young": 1e5, "poisson": 0.3,
                    "damping": {"alpha1": {"stretches": [1, 1.1], "values": [0.001, 0.002]}}})"));
  r = run("fit-parameters " + splined.string() + " --observations " + obs.string() + " -o "
      + out.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("material.damping.alpha1"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}
