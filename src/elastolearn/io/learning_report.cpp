#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_report.hpp>

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
  for (const auto& r : history)
    csv << r.iteration << ',' << r.forward_error.rms << ',' << r.forward_error.max << ','
        << r.forward_error.mean << ',' << r.control_force_rms << ',' << r.space_time_initial << ','
        << r.space_time_objective << ',' << r.space_time_iterations << ',' << r.modes << ','
        << r.centres << ',' << r.correction_misfit << ',' << r.correction_target << ','
        << r.seconds_forward << ',' << r.seconds_pod << ',' << r.seconds_constrained << ','
        << r.seconds_space_time << ',' << r.seconds_reconstruction << '\n';
  return csv.str();
}

void write_learning_report(const std::filesystem::path& dir,
    const std::vector<learn::IterationRecord>& history, const nlohmann::json& summary) {
  write_text_file_atomic(dir / "convergence.csv", convergence_csv(history));
  write_json_file(dir / "report.json", summary);
}

} // namespace elastolearn::io
