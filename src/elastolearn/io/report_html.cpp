#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/base64.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/report_html.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace elastolearn::io {

namespace {

std::string read_resource(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path.string(), "cannot read this file of the report");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Replace the first "@NAME@" of `page` by `value`.
void fill(std::string& page, const std::string& name, const std::string& value,
    const std::filesystem::path& template_path) {
  const std::string key = "@" + name + "@";
  const auto at = page.find(key);
  if (at == std::string::npos)
    throw InputError(template_path.string(), "has no " + key + " to fill");
  page.replace(at, key.size(), value);
}

std::string number(double v, const char* format = "%.4g") {
  if (!std::isfinite(v))
    return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

/// A measured value scaled, or `missing` (null: not measured).
std::string json_number(const nlohmann::json& v, double scale, const char* missing) {
  return v.is_number() ? number(scale * v.get<double>()) : missing;
}

std::string convergence_table(const LearningReport& r) {
  const double percent = r.size > 0 ? 100 / r.size : 0;
  std::string out = "<table><tr><th>iteration</th><th class=\"l\">kind</th><th>forward rms "
                    "[%]</th><th>forward max [%]</th><th>control force rms [N]</th><th>modes"
                    "</th><th>kernels</th><th>seconds</th></tr>\n";
  for (const auto& h : r.history) {
    const learn::ForwardOutcome& forward = learn::forward_of(h);
    const learn::SpaceTimeStages* stages = learn::stages_of(h);
    const learn::ForwardFitRecord* step = learn::forward_fit_of(h);
    const auto* loop = std::get_if<learn::LoopRecord>(&h);
    const char* kind = step ? (step->accepted ? "forward fit, accepted"
                               : forward.status() == learn::ForwardStatus::unstable
                               ? "forward fit, rejected unsimulated (unstable)"
                               : forward.completed() ? "forward fit, rejected"
                                                     : "forward fit, diverged (rejected)")
        : stages            ? "loop"
        : loop->damped_update()
        ? (forward.completed() ? "no better than the best (half its step next)"
                               : "diverged (half its step next)")
        : forward.completed() ? "last forward check"
                              : "diverged (the loop stops)";
    out += "<tr><td>" + std::to_string(learn::iteration_of(h)) + "</td><td class=\"l\">" + kind
        + "</td>";
    if (forward.completed()) {
      out += "<td>" + number(percent * forward.error().rms) + "</td><td>"
          + number(percent * forward.error().max) + "</td>";
    } else {
      out += "<td>-</td><td>-</td>";
    }
    const int kernels = stages ? stages->centres : step ? step->centres : 0;
    out += "<td>" + (stages ? number(stages->control_force_rms) : "-") + "</td><td>"
        + (stages ? std::to_string(stages->modes) : "-") + "</td><td>"
        + (kernels > 0 ? std::to_string(kernels) : "-") + "</td><td>"
        + number(learn::seconds_of(h), "%.2f") + "</td></tr>\n";
  }
  return out + "</table>\n";
}

std::string candidates_table(const LearningReport& r, const nlohmann::json& candidates) {
  const double percent = r.size > 0 ? 100 / r.size : 0;
  std::string out = "<p>Held out for validation: "
      + html_escape(candidates.value("validation_data", std::string())) + "</p>\n"
      + "<table><tr><th class=\"l\">candidate</th><th>validation rms [%]</th><th>validation max "
        "[%]</th><th>training rms [%]</th></tr>\n";
  for (const auto& c : candidates.at("rows")) {
    out += std::string(c.at("chosen").get<bool>() ? "<tr class=\"chosen\">" : "<tr>")
        + "<td class=\"l\">" + html_escape(c.at("label").get<std::string>())
        + (c.at("chosen").get<bool>() ? " (chosen)" : "") + "</td><td>"
        + json_number(c.at("validation_rms_m"), percent, "diverged") + "</td><td>"
        + json_number(c.at("validation_max_m"), percent, "diverged") + "</td><td>"
        + json_number(c.at("training_rms_m"), percent, "-") + "</td></tr>\n";
  }
  return out + "</table>\n";
}

} // namespace

std::string script_safe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/')
      out += '\\';
  }
  return out;
}

std::string report_html(const LearningReport& report, const std::vector<ReportPlot>& plots,
    const std::string& plots_problem, const std::filesystem::path& resource_dir) {
  const std::filesystem::path template_path = resource_dir / "report.html";
  std::string page = read_resource(template_path);

  std::string body = "<h1>" + html_escape(report.title) + "</h1>\n";
  for (const std::string& note : report.notes)
    body += "<p class=\"note\">" + html_escape(note) + "</p>\n";
  if (!plots_problem.empty())
    body += "<p class=\"note\">No plots: " + html_escape(plots_problem) + "</p>\n";
  if (report.size > 0) {
    body += "<p>Errors in % are of the object's size, the rest bounding-box diagonal "
        + number(report.size) + " m (paper 000 Table 1).</p>\n";
  }
  if (report.animation) {
    body += "<h2>Surface motion</h2>\n<p>" + html_escape(report.animation_caption)
        + "</p>\n<div id=\"viewer\"></div>\n<div id=\"controls\"><button id=\"play\">pause"
          "</button><button id=\"layout\" hidden>overlay</button><input id=\"frame\" "
          "type=\"range\" min=\"0\" max=\"0\" value=\"0\"><span "
          "id=\"frame-label\"></span><span id=\"legend\" class=\"legend\"></span></div>\n";
  }
  if (!plots.empty())
    body += "<h2>Plots</h2>\n";
  for (const ReportPlot& plot : plots) {
    body += "<figure><img alt=\"" + html_escape(plot.caption) + "\" src=\"data:image/png;base64,"
        + base64_encode(plot.png) + "\"><figcaption>" + html_escape(plot.caption)
        + "</figcaption></figure>\n";
  }
  if (report.data.contains("candidates")) {
    body += "<h2>Candidates of the recipe</h2>\n"
        + candidates_table(report, report.data.at("candidates"));
  }
  if (!report.history.empty())
    body += "<h2>Iterations</h2>\n" + convergence_table(report);
  body += "<h2>Numbers</h2>\n<details><summary>summary.json</summary><pre>"
      + html_escape(report.summary.dump(2)) + "</pre></details>\n";
  body += "<h2>Licences</h2>\n<details><summary>three.js (MIT), inlined for the "
          "animation</summary><pre>"
      + html_escape(read_resource(resource_dir / "three.LICENSE")) + "</pre></details>\n";

  // From the last placeholder to the first: each is then found before any inserted text, which
  // may contain anything.
  fill(
      page, "VIEWER", script_safe(read_resource(resource_dir / "report_viewer.js")), template_path);
  fill(page, "THREE", script_safe(read_resource(resource_dir / "three.module.min.js")),
      template_path);
  fill(page, "ANIMATION",
      script_safe(report.animation ? animation_to_json(*report.animation).dump() : "null"),
      template_path);
  fill(page, "BODY", body, template_path);
  fill(page, "TITLE", html_escape(report.title), template_path);
  return page;
}

} // namespace elastolearn::io
