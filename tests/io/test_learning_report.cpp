// The report of a learning run (`learn --report DIR`): a small made-up history and summary are
// written to convergence.csv and report.json and read back, with no temporary file left behind.
#include "io_test_util.hpp"

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_report.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace elastolearn::io {
namespace {

/// Two iterations with distinct values in every column.
std::vector<learn::IterationRecord> fake_history() {
  learn::IterationRecord a;
  a.iteration = 0;
  a.forward_error.rms = 0.25;
  a.forward_error.max = 0.5;
  a.forward_error.mean = 0.125;
  a.control_force_rms = 3;
  a.space_time_initial = 10;
  a.space_time_objective = 2.5;
  a.space_time_iterations = 4;
  a.modes = 8;
  a.centres = 12;
  a.correction_misfit = 0.75;
  a.correction_target = 1.5;
  a.seconds_forward = 1;
  a.seconds_pod = 2;
  a.seconds_constrained = 3;
  a.seconds_space_time = 4;
  a.seconds_reconstruction = 5;
  learn::IterationRecord b = a;
  b.iteration = 1;
  b.forward_error.rms = 1.0 / 3.0; // written with the stream's default 6 digits
  return { a, b };
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

TEST(LearningReport, WritesConvergenceTableAndSummary) {
  const test::ScratchDir dir;
  const nlohmann::json summary
      = { { "best_iteration", 1 }, { "seconds", 30.0 }, { "history", { { "iteration", 0 } } } };
  write_learning_report(dir.path(), fake_history(), summary);

  const std::vector<std::string> csv = lines(read_text_file(dir / "convergence.csv"));
  ASSERT_EQ(csv.size(), 3u);
  EXPECT_EQ(csv[0],
      "iteration,forward_rms_m,forward_max_m,forward_mean_m,control_force_rms_N,"
      "space_time_initial,space_time_objective,space_time_iterations,modes,centres,"
      "correction_misfit_N,correction_target_N,seconds_forward,seconds_pod,seconds_constrained,"
      "seconds_space_time,seconds_reconstruction");
  EXPECT_EQ(csv[1], "0,0.25,0.5,0.125,3,10,2.5,4,8,12,0.75,1.5,1,2,3,4,5");
  EXPECT_EQ(csv[2], "1,0.333333,0.5,0.125,3,10,2.5,4,8,12,0.75,1.5,1,2,3,4,5");
  EXPECT_EQ(convergence_csv(fake_history()), read_text_file(dir / "convergence.csv"));

  EXPECT_EQ(read_json_file(dir / "report.json"), summary);
  std::vector<std::string> files = dir.files();
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string> { "convergence.csv", "report.json" }));
}

TEST(LearningReport, EmptyHistoryHasTheHeaderOnly) {
  EXPECT_EQ(lines(convergence_csv({})).size(), 1u);
}

TEST(LearningReport, CreatesAMissingFolder) {
  const test::ScratchDir dir;
  write_learning_report(dir / "new" / "report", fake_history(), nlohmann::json::object());
  EXPECT_EQ(
      read_text_file(dir / "new" / "report" / "convergence.csv"), convergence_csv(fake_history()));
  EXPECT_EQ(read_json_file(dir / "new" / "report" / "report.json"), nlohmann::json::object());
}

TEST(LearningReport, AFolderInTheWayIsAnInputErrorNamingTheFile) {
  const test::ScratchDir dir;
  std::filesystem::create_directories(dir / "convergence.csv");
  test::expect_input_error(
      [&] { write_learning_report(dir.path(), fake_history(), nlohmann::json::object()); },
      { "convergence.csv" });
}

} // namespace
} // namespace elastolearn::io
