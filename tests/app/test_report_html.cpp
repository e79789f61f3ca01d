// The learning report end to end: `learn --report` and `evaluate --report` on a tiny bar, then
// the pages opened in headless Chromium (Debian's `chromium`; the test is skipped without it):
// they load without an error (the page records every error and console.error, and sets
// <html data-status="ok"> only after its first WebGL frame), the canvas is not blank (the
// first frame, read back, has several colours) and nothing is fetched from the network.
#include <support/cli_runner.hpp>

#include <elastolearn/io/json_fields.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <regex>

namespace fs = std::filesystem;
using elastolearn::test::run;

namespace {

const char* k_scene = R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.4, 0.1, 0.1], "cells": [8, 2, 2]},
  "material": {"model": "corotated", "young": 1.75e6, "poisson": 0.43, "density": 1000,
               "damping": {"alpha0": 0.0, "alpha1": 0.01}},
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 4e-3, "frames": 40}
})";

const char* k_truth = R"({"format": "elastolearn-material/1", "correction": null,
  "material": {"model": "neohookean", "young": 1e6, "poisson": 0.43, "density": 1000,
               "damping": {"alpha0": 0.0, "alpha1": 0.01}}})";

/// Debian's chromium (or $ELASTOLEARN_CHROMIUM), or empty.
fs::path find_chromium() {
  if (const char* c = std::getenv("ELASTOLEARN_CHROMIUM"); c && *c)
    return c;
  for (const char* c : { "/usr/bin/chromium", "/usr/bin/chromium-browser" }) {
    if (fs::exists(c))
      return c;
  }
  return {};
}

struct PageLoad {
  int exit_code = -1;
  std::string dom; ///< the DOM after the page ran (--dump-dom)
  std::string log; ///< chromium's stderr (console messages appear as ":CONSOLE(" lines)
};

/// Open `page` in headless chromium with software WebGL (SwiftShader), every network request
/// sent to a closed port, and 10 s of virtual time for the scripts.
PageLoad open_page(const fs::path& chromium, const fs::path& page, const fs::path& scratch) {
  const fs::path log = scratch / "chromium.log";
  const std::string command = "'" + chromium.string()
      + "' --headless=new --no-sandbox --disable-gpu --use-angle=swiftshader "
        "--enable-unsafe-swiftshader --no-first-run --disable-extensions "
        "--proxy-server=127.0.0.1:9 --user-data-dir='"
      + (scratch / "profile").string()
      + "' --enable-logging=stderr --v=0 --virtual-time-budget=10000 --dump-dom 'file://"
      + fs::absolute(page).string() + "' 2>'" + log.string() + "'";
  PageLoad r;
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer {};
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe))
    r.dom.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(log);
  r.log.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return r;
}

/// The page's <html> start tag, where the viewer writes its status.
std::string html_tag(const std::string& dom) {
  const auto start = dom.find("<html");
  return start == std::string::npos ? "" : dom.substr(start, dom.find('>', start) - start + 1);
}

void expect_page_renders(const fs::path& chromium, const fs::path& page, const fs::path& scratch) {
  ASSERT_TRUE(fs::exists(page)) << page;
  const PageLoad load = open_page(chromium, page, scratch);
  ASSERT_EQ(load.exit_code, 0) << load.log;
  const std::string tag = html_tag(load.dom);
  EXPECT_NE(tag.find("data-status=\"ok\""), std::string::npos) << tag << "\n"
                                                               << load.dom.substr(0, 2000) << "\n"
                                                               << load.log;
  std::smatch colours;
  ASSERT_TRUE(std::regex_search(tag, colours, std::regex(R"re(data-rendered-colours="(\d+)")re")))
      << tag;
  EXPECT_GE(std::stoi(colours[1]), 3) << "background, and the lit surface in several shades";
  EXPECT_EQ(load.log.find(":CONSOLE("), std::string::npos)
      << "the page writes nothing to the console when all is well:\n"
      << load.log;
  EXPECT_NE(load.dom.find("<div id=\"errors\" hidden=\"\">"), std::string::npos)
      << "the error box stays hidden";
}

class ReportHtmlTest : public elastolearn::test::CliTestFolder {
  protected:
  std::string path(const std::string& name) const { return (m_dir / name).string(); }
};

TEST_F(ReportHtmlTest, LearnAndEvaluateReportsOpenInChromium) {
  write("scene.json", k_scene);
  write("truth.json", k_truth);
  ASSERT_EQ(run("simulate " + path("scene.json") + " --material " + path("truth.json") + " -o "
                + path("truth.h5") + " -q")
                .exit_code,
      0);
  ASSERT_EQ(
      run("observe " + path("truth.h5") + " --visible-fraction 0.3 -o " + path("obs.h5")).exit_code,
      0);
  const auto learned = run("learn " + path("scene.json") + " --observations " + path("obs.h5")
      + " -o " + path("learned.json")
      + " --max-iterations 2 --kernels 10 --modes 8 --network-samples 4000 --report "
      + path("learn_report") + " --truth-material " + path("truth.json") + " -q");
  ASSERT_EQ(learned.exit_code, 0) << learned.output;
  EXPECT_NE(
      learned.output.find("report: " + path("learn_report") + "/report.html"), std::string::npos)
      << learned.output;
  // Every section has data: the recipe's, the training motion's and the correction's (with the
  // truth, which the scene's nominal is not).
  const auto data = elastolearn::io::read_json_file(path("learn_report/report_data.json"));
  for (const char* section :
      { "convergence", "candidates", "histograms", "frame_errors", "correction" })
    EXPECT_TRUE(data.contains(section)) << section;
  EXPECT_TRUE(data.at("correction").at("has_truth").get<bool>());
  const auto& models = data.at("frame_errors")[0].at("models");
  // Nominal, fitted nominal, the learned (chosen) and the other of the RBF and its network.
  ASSERT_EQ(models.size(), 4u) << models.dump();
  EXPECT_EQ(models[0].at("label"), "nominal");
  EXPECT_EQ(models[1].at("label"), "fitted nominal (parameter fit)");
  const std::string chosen = models[2].at("label"), other = models[3].at("label");
  EXPECT_EQ(chosen.rfind("learned (chosen: ", 0), 0u) << chosen;
  EXPECT_TRUE(
      (chosen.find("network") != std::string::npos) != (other.find("network") != std::string::npos))
      << chosen << " / " << other;
  EXPECT_TRUE(fs::exists(path("learn_report/summary.json")));
  EXPECT_TRUE(fs::exists(path("learn_report/report.json")));

  const auto evaluated = run("evaluate " + path("scene.json") + " --material "
      + path("learned.json") + " --truth " + path("truth.h5") + " --truth-material "
      + path("truth.json") + " --report " + path("evaluate_report") + " -q");
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  const auto eval_data = elastolearn::io::read_json_file(path("evaluate_report/report_data.json"));
  ASSERT_EQ(eval_data.at("frame_errors").size(), 1u);
  EXPECT_EQ(eval_data.at("frame_errors")[0].at("reference"), "the true trajectory (every vertex)");

  const fs::path chromium = find_chromium();
  if (chromium.empty())
    GTEST_SKIP() << "chromium not installed (scripts/install-deps.sh installs it)";
  expect_page_renders(chromium, path("learn_report/report.html"), m_dir);
  expect_page_renders(chromium, path("evaluate_report/report.html"), m_dir);
}

TEST_F(ReportHtmlTest, AFileInThePlaceOfThePlotsFolderStopsLearnBeforeItStarts) {
  write("scene.json", k_scene);
  write("truth.json", k_truth);
  ASSERT_EQ(run("simulate " + path("scene.json") + " --material " + path("truth.json") + " -o "
                + path("truth.h5") + " -q")
                .exit_code,
      0);
  ASSERT_EQ(
      run("observe " + path("truth.h5") + " --visible-fraction 0.3 -o " + path("obs.h5")).exit_code,
      0);
  fs::create_directories(path("report"));
  write("report/plots", "not a folder");
  const auto learned = run("learn " + path("scene.json") + " --observations " + path("obs.h5")
      + " -o " + path("learned.json") + " --report " + path("report") + " -q");
  EXPECT_NE(learned.exit_code, 0);
  EXPECT_NE(learned.output.find(path("report/plots")), std::string::npos) << learned.output;
  EXPECT_EQ(learned.output.find("learning from"), std::string::npos) << "refused before learning:\n"
                                                                     << learned.output;
  EXPECT_FALSE(fs::exists(path("learned.json")));
}

TEST_F(ReportHtmlTest, ATrueMaterialWithoutAReportIsRefused) {
  for (const char* command : { "learn s.json --observations o.h5 -o l.json --truth-material t.json",
           "evaluate s.json --material l.json --truth t.h5 --truth-material t.json" }) {
    const auto r = run(command);
    EXPECT_NE(r.exit_code, 0) << command;
    EXPECT_NE(r.output.find("--truth-material: is used by the report only"), std::string::npos)
        << r.output;
  }
}

} // namespace
