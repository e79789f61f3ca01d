// The report of a learning run (`learn --report DIR`, docs/report.md): a small made-up report is
// written and its files read back — the tables and JSON exactly, the plots drawn when
// matplotlib is there (and the rest written when Python is not), the page self-contained.
#include "io_test_util.hpp"

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_report.hpp>
#include <elastolearn/io/report_data.hpp>
#include <elastolearn/io/report_html.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace elastolearn::io {
namespace {

/// Two loop iterations with distinct values in every column, a diverged one (a damped update)
/// and a forward-fit step.
std::vector<learn::IterationRecord> fake_history() {
  learn::ErrorSummary e;
  e.rms = 0.25;
  e.max = 0.5;
  e.mean = 0.125;
  learn::SpaceTimeStages t;
  t.control_force_rms = 3;
  t.space_time_initial = 10;
  t.space_time_objective = 2.5;
  t.space_time_iterations = 4;
  t.modes = 8;
  t.centres = 12;
  t.correction_misfit = 0.75;
  t.correction_target = 1.5;
  t.seconds_pod = 2;
  t.seconds_constrained = 3;
  t.seconds_space_time = 4;
  t.seconds_reconstruction = 5;
  const learn::LoopRecord a { 0, learn::ForwardOutcome::completed(e, 1), t };
  e.rms = 1.0 / 3.0; // written with the stream's default 6 digits
  const learn::LoopRecord b { 1, learn::ForwardOutcome::completed(e, 1), t };
  const learn::LoopRecord c { 2, learn::ForwardOutcome::diverged("diverged at frame 9", 7),
    learn::DampedUpdate {} };
  const learn::ForwardFitRecord d { 3,
    learn::ForwardOutcome::completed({ 0.25, 0.0625, 0.125, 1, 2, 30 }, 6), true, 12 };
  return { a, b, c, d };
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

/// A report with the made-up history and every field a page shows.
LearningReport fake_report() {
  LearningReport r;
  r.title = "a <made-up> report";
  r.size = 0.5;
  r.history = fake_history();
  r.data["convergence"] = convergence_json(r.history);
  r.summary = { { "best_iteration", 1 }, { "seconds", 30.0 } };
  r.provenance = nlohmann::json { { "history", { { "iteration", 0 } } } };
  r.notes = { "a note" };
  return r;
}

bool matplotlib_available() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
}

/// Sets an environment variable for the scope of a test.
class ScopedEnv {
  public:
  ScopedEnv(const char* name, const char* value)
      : m_name(name) {
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() { ::unsetenv(m_name); }

  private:
  const char* m_name;
};

TEST(LearningReport, WritesEveryFile) {
  if (std::getenv("ELASTOLEARN_PYTHON"))
    GTEST_SKIP() << "ELASTOLEARN_PYTHON is set: this test checks the default interpreter";
  const test::ScratchDir dir;
  const LearningReport report = fake_report();
  const ReportOutcome outcome = write_learning_report(dir.path(), report);

  const std::vector<std::string> csv = lines(read_text_file(dir / "convergence.csv"));
  ASSERT_EQ(csv.size(), 5u);
  EXPECT_EQ(csv[0],
      "iteration,forward_rms_m,forward_max_m,forward_mean_m,control_force_rms_N,"
      "space_time_initial,space_time_objective,space_time_iterations,modes,centres,"
      "correction_misfit_N,correction_target_N,seconds_forward,seconds_pod,seconds_constrained,"
      "seconds_space_time,seconds_reconstruction");
  EXPECT_EQ(csv[1], "0,0.25,0.5,0.125,3,10,2.5,4,8,12,0.75,1.5,1,2,3,4,5");
  EXPECT_EQ(csv[2], "1,0.333333,0.5,0.125,3,10,2.5,4,8,12,0.75,1.5,1,2,3,4,5");
  // What a step did not measure is empty: the diverged step's errors and every step's columns
  // of the trajectory stages it did not run (a forward-fit step has its kernels).
  EXPECT_EQ(csv[3], "2,,,,,,,,,,,,7,0,0,0,0");
  EXPECT_EQ(csv[4], "3,0.125,0.25,0.0625,,,,,,12,,,6,0,0,0,0");
  EXPECT_EQ(read_json_file(dir / "report.json"), *report.provenance);
  EXPECT_EQ(read_json_file(dir / "summary.json"), report.summary);
  const nlohmann::json data = read_json_file(dir / "report_data.json");
  EXPECT_EQ(data.at("format"), "elastolearn-report-data/1");
  EXPECT_EQ(data.at("convergence"), report.data.at("convergence"));
  EXPECT_EQ(data.at("size_m"), 0.5);

  if (matplotlib_available()) {
    EXPECT_EQ(outcome.plots_problem, "");
    EXPECT_EQ(outcome.plots, std::vector<std::string> { "plots/convergence.png" })
        << "only the convergence has data";
    const std::string png = read_text_file(dir / "plots" / "convergence.png");
    EXPECT_EQ(png.substr(1, 3), "PNG");
  } else {
    EXPECT_NE(outcome.plots_problem, "");
  }
  const std::string html = read_text_file(dir / "report.html");
  EXPECT_NE(html.find("<h1>a &lt;made-up&gt; report</h1>"), std::string::npos);
  EXPECT_NE(html.find("a note"), std::string::npos);
  // The convergence table names each kind of step.
  for (const char* kind :
      { "<td class=\"l\">loop</td>", "diverged (half its step next)", "forward fit, accepted" })
    EXPECT_NE(html.find(kind), std::string::npos) << kind;
  EXPECT_EQ(html.find("@BODY@"), std::string::npos);
  EXPECT_EQ(html.find("@THREE@"), std::string::npos);
  EXPECT_NE(html.find("Copyright 2010-2024 Three.js Authors"), std::string::npos)
      << "three.js is inlined";
  if (outcome.plots_problem.empty()) {
    EXPECT_NE(html.find("src=\"data:image/png;base64,iVBOR"), std::string::npos);
  }

  std::vector<std::string> files = dir.files();
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files,
      (std::vector<std::string> { "convergence.csv", "plots", "report.html", "report.json",
          "report_data.json", "summary.json" }))
      << "no temporary file is left behind";
}

TEST(LearningReport, ThePageNeedsNoNetwork) {
  const test::ScratchDir dir;
  const ScopedEnv python("ELASTOLEARN_PYTHON", "/bin/true"); // no plots needed: faster
  write_learning_report(dir.path(), fake_report());
  const std::string html = read_text_file(dir / "report.html");
  // Nothing is fetched: no external script, style sheet, image or frame.
  const std::regex external(R"((src|href)\s*=\s*["']?\s*(https?:|//))", std::regex::icase);
  EXPECT_FALSE(std::regex_search(html, external));
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("@import"), std::string::npos);
}

TEST(LearningReport, WithoutPythonTheRestIsWrittenAndThePageSaysWhy) {
  const test::ScratchDir dir;
  const ScopedEnv python("ELASTOLEARN_PYTHON", "/nonexistent/python3");
  const ReportOutcome outcome = write_learning_report(dir.path(), fake_report());
  EXPECT_NE(outcome.plots_problem.find("/nonexistent/python3 not found"), std::string::npos)
      << outcome.plots_problem;
  EXPECT_TRUE(outcome.plots.empty());
  EXPECT_TRUE(std::filesystem::exists(dir / "summary.json"));
  const std::string html = read_text_file(dir / "report.html");
  EXPECT_NE(html.find("No plots: /nonexistent/python3 not found"), std::string::npos);
  EXPECT_NE(describe_report(dir.path(), outcome).find("no plots"), std::string::npos);
}

TEST(LearningReport, AFailingScriptIsReportedWithItsLastLine) {
  const test::ScratchDir dir;
  // /bin/false as the interpreter: it fails without a word.
  const ScopedEnv python("ELASTOLEARN_PYTHON", "/bin/false");
  const ReportOutcome outcome = write_learning_report(dir.path(), fake_report());
  EXPECT_NE(outcome.plots_problem.find("report_plots.py failed (exit code 1)"), std::string::npos)
      << outcome.plots_problem;
  EXPECT_TRUE(std::filesystem::exists(dir / "report.html"));
}

TEST(LearningReport, StalePlotsOfAnEarlierReportAreRemoved) {
  if (!matplotlib_available())
    GTEST_SKIP() << "needs python3-matplotlib";
  const test::ScratchDir dir;
  std::filesystem::create_directories(dir / "plots");
  write_text_file_atomic(dir / "plots" / "damping.png", "an old plot");
  const ReportOutcome outcome = write_learning_report(dir.path(), fake_report());
  EXPECT_FALSE(std::filesystem::exists(dir / "plots" / "damping.png"));
  EXPECT_EQ(outcome.plots.size(), 1u);
}

TEST(LearningReport, EmptyHistoryHasTheHeaderOnly) {
  EXPECT_EQ(lines(convergence_csv({})).size(), 1u);
}

TEST(LearningReport, CreatesAMissingFolder) {
  const test::ScratchDir dir;
  const ScopedEnv python("ELASTOLEARN_PYTHON", "/bin/true"); // no plots needed: faster
  write_learning_report(dir / "new" / "report", fake_report());
  EXPECT_EQ(
      read_text_file(dir / "new" / "report" / "convergence.csv"), convergence_csv(fake_history()));
}

TEST(LearningReport, ScriptTextCannotCloseItsScriptElement) {
  EXPECT_EQ(script_safe("a</script>b"), "a<\\/script>b");
  EXPECT_EQ(script_safe("x < y"), "x < y");
  EXPECT_EQ(nlohmann::json::parse(script_safe(nlohmann::json("</script>").dump())), "</script>")
      << "still the same JSON string";
  EXPECT_EQ(html_escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
}

TEST(LearningReport, AFolderInTheWayIsAnInputErrorNamingTheFile) {
  const test::ScratchDir dir;
  std::filesystem::create_directories(dir / "convergence.csv");
  test::expect_input_error(
      [&] { write_learning_report(dir.path(), fake_report()); }, { "convergence.csv" });
}

} // namespace
} // namespace elastolearn::io
