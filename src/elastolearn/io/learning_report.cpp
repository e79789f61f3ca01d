#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_report.hpp>
#include <elastolearn/io/report_html.hpp>
#include <elastolearn/io/report_resources.hpp>
#include <elastolearn/mesh/external_program.hpp>

#include <fstream>
#include <sstream>

namespace elastolearn::io {

std::string convergence_csv(const std::vector<learn::IterationRecord>& history) {
  std::ostringstream csv;
  csv << "iteration,forward_rms_m,forward_max_m,forward_mean_m,control_force_rms_N,space_time_"
         "initial,"
         "space_time_objective,space_time_iterations,modes,centres,correction_misfit_N,correction_"
         "target_N,"
         "seconds_forward,seconds_pod,seconds_constrained,seconds_space_time,seconds_"
         "reconstruction\n";
  // A value the step did not measure is an empty cell: the forward error of a simulation that
  // did not complete, the trajectory stages' columns of a step that did not run them.
  for (const auto& r : history) {
    const learn::ForwardOutcome& forward = learn::forward_of(r);
    csv << learn::iteration_of(r) << ',';
    if (forward.completed())
      csv << forward.error().rms << ',' << forward.error().max << ',' << forward.error().mean
          << ',';
    else
      csv << ",,,";
    if (const learn::SpaceTimeStages* t = learn::stages_of(r))
      csv << t->control_force_rms << ',' << t->space_time_initial << ',' << t->space_time_objective
          << ',' << t->space_time_iterations << ',' << t->modes << ',' << t->centres << ','
          << t->correction_misfit << ',' << t->correction_target << ',';
    else if (const learn::ForwardFitRecord* step = learn::forward_fit_of(r))
      csv << ",,,,," << step->centres << ",,,";
    else
      csv << ",,,,,,,,";
    const learn::SpaceTimeStages none;
    const learn::SpaceTimeStages& t = learn::stages_of(r) ? *learn::stages_of(r) : none;
    csv << forward.seconds() << ',' << t.seconds_pod << ',' << t.seconds_constrained << ','
        << t.seconds_space_time << ',' << t.seconds_reconstruction << '\n';
  }
  return csv.str();
}

namespace {

/// The plots report_plots.py draws (when their data are there), in the page's order.
struct PlotFile {
  const char* file;
  const char* caption;
};
constexpr PlotFile plot_files[] = {
  { "convergence.png",
      "Forward error at the observed vertices (RMS and max) and control-force RMS per iteration "
      "of the learning loop; forward-fit steps follow it." },
  { "candidates.png",
      "Validation error (RMS on the held-out data) of each candidate the recipe chooses among; "
      "the chosen one is marked." },
  { "histograms.png",
      "Histogram of the vertex position errors of every (frame, observed vertex) per candidate, "
      "as paper 000 Fig. 18; errors below the first bin (the initial state's zeros among them) "
      "are counted in it." },
  { "frame_errors.png",
      "Error per frame (largest over the compared vertices) of the nominal, the fitted-parameter "
      "baseline and the learned model(s)." },
  { "correction_uniaxial.png",
      "The learned correction N(F̂, 0) along uniaxial stretch σ = (s, 1, 1), along "
      "the stretched axis and across it, against the truth's where known; shaded: the training "
      "motion's stretches." },
  { "correction_scale.png",
      "Magnitude of the learned correction along the deformation scale ‖F̂ − "
      "(1, 1, 1)‖ (paper 000 Fig. 6) in six directions, against the truth's where known; "
      "solid where the training motion's stretches reach." },
  { "damping.png",
      "The learned damping law: the stiffness-damping coefficient α₁ + "
      "Δα₁ along the largest stretch, against the nominal's α₁ and "
      "the truth's where known; shaded: the training motion's stretches." },
};

std::string read_binary(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Run report_plots.py on `data` into `plots_dir`; the problem, or "" if it drew.
std::string draw_plots(const std::filesystem::path& resources, const std::filesystem::path& data,
    const std::filesystem::path& plots_dir) {
  const std::filesystem::path python = report_python();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(python, ec))
    return python.string() + " not found (install python3 and python3-matplotlib)";
  const mesh::TemporaryDirectory scratch("elastolearn-report");
  const mesh::ProgramResult run = mesh::run_program(python,
      { (resources / "report_plots.py").string(), data.string(), plots_dir.string() },
      scratch.path() / "plots.log");
  if (run.ok())
    return "";
  std::string output = run.output;
  while (!output.empty() && (output.back() == '\n' || output.back() == ' '))
    output.pop_back();
  if (const auto line = output.rfind('\n'); line != std::string::npos)
    output = output.substr(line + 1); // the last line says what went wrong
  return "report_plots.py failed ("
      + (run.signal ? "signal " + std::to_string(run.signal)
                    : "exit code " + std::to_string(run.exit_code))
      + "): " + output;
}

} // namespace

std::vector<CommandOutput> report_outputs(
    const std::filesystem::path& dir, const std::string& role) {
  std::vector<CommandOutput> outputs = { { dir, role, OutputKind::folder },
    { dir / "plots", role + ": its plots folder", OutputKind::folder } };
  for (const char* name :
      { "convergence.csv", "report.json", "summary.json", "report_data.json", "report.html" })
    outputs.push_back({ dir / name, role + ": its " + name });
  for (const PlotFile& p : plot_files)
    outputs.push_back({ dir / "plots" / p.file, role + ": its plots/" + p.file });
  return outputs;
}

ReportOutcome write_learning_report(
    const std::filesystem::path& dir, const LearningReport& report) {
  std::error_code ec;
  std::filesystem::create_directories(dir / "plots", ec);
  if (ec)
    throw InputError((dir / "plots").string(), "cannot create the folder: " + ec.message());
  write_text_file_atomic(dir / "convergence.csv", convergence_csv(report.history));
  if (report.provenance)
    write_json_file(dir / "report.json", *report.provenance);
  write_json_file(dir / "summary.json", report.summary);
  nlohmann::json data = report.data;
  data["format"] = "elastolearn-report-data/1";
  data["title"] = report.title;
  data["size_m"] = report.size;
  write_json_file(dir / "report_data.json", data);

  const std::filesystem::path resources = report_resource_dir();
  // Plots of an earlier report in the same folder must not show up in this one.
  for (const PlotFile& p : plot_files)
    std::filesystem::remove(dir / "plots" / p.file, ec);
  ReportOutcome outcome;
  outcome.plots_problem = draw_plots(resources, dir / "report_data.json", dir / "plots");
  std::vector<ReportPlot> plots;
  for (const PlotFile& p : plot_files) {
    const std::filesystem::path png = dir / "plots" / p.file;
    if (!std::filesystem::is_regular_file(png, ec))
      continue;
    outcome.plots.push_back((std::filesystem::path("plots") / p.file).string());
    plots.push_back({ p.caption, read_binary(png) });
  }
  write_text_file_atomic(
      dir / "report.html", report_html(report, plots, outcome.plots_problem, resources));
  return outcome;
}

std::string describe_report(const std::filesystem::path& dir, const ReportOutcome& outcome) {
  return "report: " + (dir / "report.html").string() + " ("
      + (outcome.plots_problem.empty() ? std::to_string(outcome.plots.size()) + " plots"
                                       : "no plots: " + outcome.plots_problem)
      + ")";
}

} // namespace elastolearn::io
