#pragma once
/// \file The report of a learning run (`learn --report DIR`, `evaluate --report DIR`, `demo`;
/// docs/report.md): in DIR
///   - convergence.csv: one row per iteration of the loop's history (columns: convergence_csv);
///   - report.json: the learned material's training provenance (learn only);
///   - summary.json: the command's numbers;
///   - report_data.json: what the plots show (report_data.hpp);
///   - plots/*.png: drawn by share/elastolearn/report/report_plots.py (matplotlib) from it;
///   - report.html: one self-contained page (plots, tables and a WebGL animation of the surface
///     motion, every script and data inlined: it opens offline).
/// Every file is written atomically (core/atomic_file.hpp). Without Python or matplotlib the
/// plots are missing, the page says why, and everything else is still written.
#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/io/report_animation.hpp>
#include <elastolearn/learn/learning_loop.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// What a report shows: filled by the commands with report_builder.hpp, written by
/// write_learning_report.
struct LearningReport {
  std::string title; ///< the page's heading
  double size = 0; ///< rest bounding-box diagonal [m]; errors are also shown as % of it
  std::vector<learn::IterationRecord> history; ///< the loop's (empty: no convergence table)
  /// Plot data by section ("convergence", "candidates", "histograms", "frame_errors" (an array
  /// of panels), "correction"): report_data.hpp.
  nlohmann::json data = nlohmann::json::object();
  std::optional<SurfaceAnimation> animation;
  std::string animation_caption;
  nlohmann::json summary = nlohmann::json::object(); ///< summary.json: the command's numbers
  std::optional<nlohmann::json> provenance; ///< report.json (learn: the learned file's training)
  std::vector<std::string> notes; ///< shown at the top of the page
};

/// The convergence table: a header line, then per record its iteration, forward error (rms, max,
/// mean [m]), control force RMS [N], space-time objective (initial, final, iterations), modes,
/// centres, correction misfit and target [N] and the seconds of each stage, comma-separated
/// (doubles as `std::ostream` writes them by default).
std::string convergence_csv(const std::vector<learn::IterationRecord>& history);

/// What write_learning_report wrote.
struct ReportOutcome {
  std::vector<std::string> plots; ///< PNG files drawn, relative to the folder
  /// Why the plots are missing (Python or matplotlib not found, the script failed), empty if drawn.
  std::string plots_problem;
};

/// The folder `dir` and every file a report writes there, for the command's
/// check_command_paths (`role` names the option, e.g. "--report folder").
std::vector<CommandOutput> report_outputs(
    const std::filesystem::path& dir, const std::string& role);

/// Write the report into `dir` (created if missing). The plots are drawn by running
/// report_python() on report_plots.py from report_resource_dir(); if that fails, the outcome says
/// why and the rest is written all the same. Throws InputError naming a file that cannot be
/// written, or the report's files (template, three.js) when they cannot be found.
ReportOutcome write_learning_report(const std::filesystem::path& dir, const LearningReport& report);

/// One line for users: "report: DIR/report.html (7 plots)", or "report: DIR/report.html (no
/// plots: <why>)".
std::string describe_report(const std::filesystem::path& dir, const ReportOutcome& outcome);

} // namespace elastolearn::io
