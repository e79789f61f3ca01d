#pragma once
/// \file The report of a learning run (`learn --report DIR`, the Python `learn(report=...)`;
/// docs/report.md): the recipe's sections on the first motion (convergence, candidates'
/// validation errors, histograms, error per frame), the written material's correction against
/// the truth when known, the learned file's provenance.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/io/learning_report.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/learn/learning_recipe.hpp>

#include <filesystem>
#include <span>
#include <string>

namespace elastolearn::io {

struct LearningRunReportInputs {
  std::string scene_path; ///< the scene or training-set file, as given
  std::string output_path; ///< the learned material file (or a name for it)
  std::span<const learn::Motion> motions;
  const learn::RecipeResult* result = nullptr;
  const MaterialFile* learned = nullptr; ///< learned_material_file of `result`
  const fem::MaterialModel* truth = nullptr; ///< the true material, when known
  std::string truth_path; ///< names it in the summary (empty: unknown)
};

/// Write the report into `dir` (write_learning_report); simulates every candidate once more on
/// the first motion for the plots. Returns what was written. Throws InputError as
/// write_learning_report does.
ReportOutcome write_learning_run_report(
    const std::filesystem::path& dir, const LearningRunReportInputs& inputs);

} // namespace elastolearn::io
