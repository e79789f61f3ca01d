// End-to-end test of the coarsening commands (paper 000 §7.3, examples/09_coarsening): a layered
// fine bar's motion observed at a coarse mesh's vertices (`observe --onto`), a coarse material
// evaluated against those observations (`evaluate --truth obs.h5`) and fitted to a training set
// of them (`fit-parameters training.json`).
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <support/cli_runner.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using namespace elastolearn;
using elastolearn::test::run;

namespace {

/// A 0.2 m bar clamped at x = 0, spinning about its axis at the start (30 frames); `cells` and
/// `material` open.
std::string bar(const std::string& cells, const std::string& material) {
  return R"({"format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.2, 0.04, 0.04], "cells": )"
      + cells + R"(},
  "material": )"
      + material + R"(,
  "fixed": [{"min": "x"}],
  "initial": {"type": "velocity", "angular_velocity": [10, 0, 0], "center": [0.1, 0.02, 0.02]},
  "time": {"dt": 0.002, "frames": 30}})";
}

const char* k_layered = R"({"model": "corotated", "young": 1e5, "poisson": 0.4, "density": 1000,
  "regions": [{"select": {"layers": {"axis": "x", "period": 0.05, "start": 0.025,
                                     "thickness": 0.025}}, "young": 1e6}]})";
const char* k_homogeneous
    = R"({"model": "corotated", "young": 3e5, "poisson": 0.4, "density": 1000})";

class CliCoarseningTest : public elastolearn::test::CliTestFolder {
  protected:
  /// The fine layered bar's motion observed at every vertex of the coarse bar.
  void observe_fine() {
    m_fine = write("fine.json", bar("[8, 2, 2]", k_layered));
    m_coarse = write("coarse.json", bar("[4, 1, 1]", k_homogeneous));
    const auto s
        = run("simulate " + m_fine.string() + " -o " + (m_dir / "fine.h5").string() + " -q");
    ASSERT_EQ(s.exit_code, 0) << s.output;
    const auto o = run("observe " + (m_dir / "fine.h5").string() + " --onto " + m_coarse.string()
        + " --all -o " + (m_dir / "obs.h5").string());
    ASSERT_EQ(o.exit_code, 0) << o.output;
    EXPECT_NE(o.output.find("observed all 20 vertices"), std::string::npos) << o.output;
  }
  fs::path m_fine, m_coarse;
};

} // namespace

TEST_F(CliCoarseningTest, ObservesTheFineMotionAtTheCoarseVertices) {
  observe_fine();
  // The coarse vertices are fine vertices (a nested grid): the observation is the fine
  // trajectory at those vertices, exactly.
  const io::TrajectoryData fine = io::read_trajectory_h5(m_dir / "fine.h5");
  const observe::Observation obs = io::read_observation_h5(m_dir / "obs.h5");
  ASSERT_EQ(obs.num_observed(), 20);
  ASSERT_EQ(obs.num_frames(), 31);
  double moved = 0;
  for (int j = 0; j < 20; ++j) {
    int match = -1;
    for (int v = 0; v < fine.rest_positions.rows() && match < 0; ++v)
      if ((fine.rest_positions.row(v) - obs.positions[0].row(j)).norm() < 1e-12)
        match = v;
    ASSERT_GE(match, 0) << "coarse vertex " << j;
    for (int t = 0; t <= 30; ++t)
      EXPECT_EQ(obs.positions[t].row(j), fine.positions[t].row(match)) << "frame " << t;
    moved = std::max(moved, (obs.positions[30].row(j) - obs.positions[0].row(j)).norm());
  }
  EXPECT_GT(moved, 1e-3); // the bar did twist
}

TEST_F(CliCoarseningTest, EvaluatesAndFitsACoarseMaterialAgainstTheObservations) {
  observe_fine();
  write("material.json",
      R"({"format": "elastolearn-material/1", "material": )" + std::string(k_homogeneous)
          + R"(, "correction": null, "training": {}})");
  const auto e = run("evaluate " + m_coarse.string() + " --material "
      + (m_dir / "material.json").string() + " --truth " + (m_dir / "obs.h5").string() + " --json "
      + (m_dir / "eval.json").string() + " -q");
  ASSERT_EQ(e.exit_code, 0) << e.output;
  EXPECT_NE(e.output.find("observations of 20 vertices"), std::string::npos) << e.output;
  const auto report = io::read_json_file(m_dir / "eval.json");
  EXPECT_EQ(report.at("truth_vertices"), 20);
  EXPECT_GT(report.at("nominal").at("err_L_percent").get<double>(), 0.0);
  // The report animates the true motion of every vertex: refused with observations.
  const auto r
      = run("evaluate " + m_coarse.string() + " --material " + (m_dir / "material.json").string()
          + " --truth " + (m_dir / "obs.h5").string() + " --report " + (m_dir / "report").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--report"), std::string::npos) << r.output;

  // fit-parameters over a training set: one fit to its motions, recorded in the file.
  write("set.json", R"({"format": "elastolearn-training/1",
      "motions": [{"scene": "coarse.json", "observations": "obs.h5"}]})");
  const auto f = run("fit-parameters " + (m_dir / "set.json").string() + " -o "
      + (m_dir / "fitted.json").string() + " --fit young --max-iterations 3 -q");
  ASSERT_EQ(f.exit_code, 0) << f.output;
  const io::MaterialFile fitted = io::read_material_file(m_dir / "fitted.json");
  EXPECT_EQ(fitted.training.at("motions"), 1);
  EXPECT_LT(fitted.training.at("final_rms_error_m").get<double>(),
      fitted.training.at("initial_rms_error_m").get<double>());
  const auto both = run("fit-parameters " + (m_dir / "set.json").string() + " --observations "
      + (m_dir / "obs.h5").string() + " -o " + (m_dir / "x.json").string());
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.output.find("--observations"), std::string::npos) << both.output;
}

TEST_F(CliCoarseningTest, AVertexOutsideTheFineMeshIsAnErrorNamingIt) {
  observe_fine();
  // A coarse bar 1 cm longer than the fine one: its far-end vertices lie outside.
  const auto longer = write("longer.json",
      std::string(R"({"format": "elastolearn-scene/1",
      "mesh": {"type": "box", "size": [0.21, 0.04, 0.04], "cells": [4, 1, 1]},
      "material": )")
          + k_homogeneous + R"(, "fixed": [{"min": "x"}], "time": {"dt": 0.002, "frames": 30}})");
  const auto o = run("observe " + (m_dir / "fine.h5").string() + " --onto " + longer.string()
      + " --all -o " + (m_dir / "bad.h5").string());
  EXPECT_NE(o.exit_code, 0);
  EXPECT_NE(o.output.find("longer.json: vertex"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("outside the mesh"), std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(m_dir / "bad.h5"));
  // fit-parameters and learn refuse the heterogeneous scene.
  const auto f = run("fit-parameters " + m_fine.string() + " --observations "
      + (m_dir / "obs.h5").string() + " -o " + (m_dir / "x.json").string());
  EXPECT_NE(f.exit_code, 0);
  EXPECT_NE(f.output.find("material.regions"), std::string::npos) << f.output;
}
