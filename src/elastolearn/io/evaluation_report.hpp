#pragma once
/// \file The report of an evaluation (`evaluate --report DIR`, the Python `evaluate(report=...)`;
/// docs/report.md): the error per frame of the nominal, the fitted-parameter baseline (the
/// learned file's nominal without its correction), the learned material and, for a network, its
/// RBF teacher; the animation of the true and learned motions; the learned correction's curves.
#include <elastolearn/core/progress.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/io/learning_report.hpp>
#include <elastolearn/io/material_evaluation.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/sim/scene.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// What the evaluation compared, as evaluate_material and evaluation_to_json took it.
struct EvaluationReportInputs {
  const sim::Scene* scene = nullptr; ///< the test scene (its material is the nominal)
  std::string scene_path; ///< names the scene in the title and summary
  const MaterialFile* material = nullptr; ///< the learned material file
  std::string material_path;
  const std::vector<VecX>* truth = nullptr; ///< flat 3n frames (read_truth_trajectory)
  std::string truth_path;
  const fem::MaterialModel* true_material = nullptr; ///< the true material, when known
};

/// Write the report of `evaluation` into `dir` (write_learning_report): it simulates the
/// fitted-parameter baseline and, for a network, its teacher (with `progress(label)`'s progress
/// display, none if `progress` is empty). Returns what was written. Throws InputError as
/// write_learning_report does, or for a teacher that is not a valid correction.
ReportOutcome write_evaluation_report(const std::filesystem::path& dir,
    const EvaluationReportInputs& inputs, const MaterialEvaluation& evaluation,
    const std::function<ProgressCallback(const std::string& label)>& progress = {});

} // namespace elastolearn::io
