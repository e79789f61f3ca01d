#pragma once
/// \file report.html of a learning report: the template share/elastolearn/report/report.html
/// filled with the report's text, tables, plots (PNG, base64) and animation data, three.js and
/// the viewer script inlined, so that the page is one file that opens offline.
#include <elastolearn/core/format.hpp> // html_escape
#include <elastolearn/io/learning_report.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn::io {

/// A drawn plot to show.
struct ReportPlot {
  std::string caption;
  std::string png; ///< the PNG file's bytes
};

/// `text` made safe to inline between <script> tags: every "</" becomes "<\/" (the same string
/// in JSON and in JavaScript string, regex and template literals).
std::string script_safe(const std::string& text);

/// The page. `resource_dir` holds report.html, report_viewer.js, three.module.min.js and
/// three.LICENSE (report_resource_dir()); `plots_problem` is shown when non-empty. Throws
/// InputError naming a resource file that cannot be read.
std::string report_html(const LearningReport& report, const std::vector<ReportPlot>& plots,
    const std::string& plots_problem, const std::filesystem::path& resource_dir);

} // namespace elastolearn::io
