#pragma once
/// \file The data a learning report plots, as JSON sections of DIR/report_data.json (read by
/// share/elastolearn/report/report_plots.py; layout in docs/report.md). Each function builds one
/// section from the library's results; report_builder.hpp runs the simulations they need.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/learn/error_distribution.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/material/stretch_range.hpp>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace elastolearn::io {

/// "convergence": per record of the loop's history its iteration, whether it is a forward-fit
/// step, whether its forward simulation completed, the forward error (rms, max [m]) and the
/// control-force RMS [N] (null where not measured: a diverged simulation, a forward-fit step).
nlohmann::json convergence_json(const std::vector<learn::IterationRecord>& history);

/// A candidate's label for plots and tables: "nominal", "fitted nominal", "loop 3",
/// "forward fit 9".
std::string candidate_label(const learn::Candidate& candidate);

/// "candidates": per candidate of the recipe its label, kind, iteration, whether its validation
/// simulation completed, its validation and training RMS errors [m] (null if it diverged) and
/// whether it was chosen; plus "validation_data" (what was held out).
nlohmann::json candidates_json(const learn::RecipeResult& result);

/// One model's errors per frame against a panel's reference.
struct ModelFrameErrors {
  std::string label;
  learn::FrameErrors errors; ///< [m]
  bool completed = true; ///< false: the simulation stopped early (fewer frames)
};

/// One panel of "frame_errors": {"title", "reference", "dt", "models": [{"label", "completed",
/// "max_m": [...], "rms_m": [...]}]}.
nlohmann::json frame_errors_panel(const std::string& title, const std::string& reference, double dt,
    const std::vector<ModelFrameErrors>& models);

/// One histogram of "histograms": an iteration's (or another candidate's) error counts.
struct HistogramRow {
  std::string label;
  std::vector<long> counts; ///< per bin (empty if the simulation diverged)
  bool completed = true;
};

/// "histograms": {"reference", "bin_edges_m", "rows": [{"label", "completed", "counts"}]}.
nlohmann::json histograms_json(const std::string& reference, const std::vector<double>& edges,
    const std::vector<HistogramRow>& rows);

/// "correction": the learned material's correction and damping law (learn/correction_curves.hpp),
/// and the truth's where known:
///  - "uniaxial": {"stretch", "inside", "learned_axial", "learned_lateral", "truth_axial",
///    "truth_lateral"}: the stress [Pa] along the stretched axis and across it, σ = (s, 1, 1);
///  - "deformation_scale": [{"label", "scale", "inside", "learned_norm", "truth_norm"}]: ‖N‖ [Pa]
///    along six directions of F̂ − (1, 1, 1);
///  - "damping": {"stretch", "inside", "nominal_alpha1", "learned_alpha1", "truth_alpha1"}: α₁
///    [s] along the largest stretch, the nominal's without and the learned with its Δα₁.
/// The reference nominal is `learned.elastic` (the learned file's nominal, i.e. the fitted one),
/// so "learned_*" is N(F̂, 0) and "truth_*" what N should be: the truth's stress minus the
/// nominal's ("truth_*" are null without `truth`). "inside": within `training` (all false
/// without). The plotted stretch range is three times the training's deviation from 1
/// (within [0.05, 0.5]; 0.3 without a training range).
nlohmann::json correction_curves_json(const fem::MaterialModel& learned,
    const fem::MaterialModel* truth, const material::StretchRange* training);

} // namespace elastolearn::io
