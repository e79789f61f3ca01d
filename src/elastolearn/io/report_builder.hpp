#pragma once
/// \file Filling a learning report (learning_report.hpp) from what the commands computed: the
/// recipe's run (convergence, candidates, error histograms and error per frame on the training
/// motion, its animation), a test motion with its truth (error per frame, the animation of true
/// against learned motion) and the learned correction's curves. The simulations the plots need
/// run here, not in the commands.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/io/learning_report.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/material/stretch_range.hpp>
#include <elastolearn/sim/scene.hpp>

#include <span>
#include <string>
#include <vector>

namespace elastolearn::io {

/// A material to compare, with its label in plots ("network", ...).
struct LabelledModel {
  std::string label;
  fem::MaterialModel material;
};

/// Bins of the error histograms: log-spaced from the smallest positive error (at least 1e-6 of
/// the object's size) to the largest.
inline constexpr int report_histogram_bins = 24;

/// The recipe's sections: its history ("convergence"), its candidates ("candidates"), and, on
/// the first motion against its observations (all frames, training and held-out), each
/// candidate's error histogram ("histograms") and the error per frame ("frame_errors") of the
/// nominal, the fitted nominal, the chosen material and `extra` (e.g. the network distilled from
/// it), each simulated here (one simulation per candidate and extra model). The animation shows
/// the chosen material's motion with the observed vertices. Sets report.size and history.
void add_recipe_sections(LearningReport& report, std::span<const learn::Motion> motions,
    const learn::RecipeResult& result, const std::vector<LabelledModel>& extra = {});

/// A simulated run of a test scene, to compare with its truth.
struct LabelledRun {
  std::string label;
  const std::vector<VecX>* frames = nullptr; ///< flat 3n, frame 0 = initial state
  bool completed = true;
};

/// The test motion's sections: a "frame_errors" panel of each run against `truth` at every
/// vertex, and the animation of the truth (wireframe) against the run labelled `animated`
/// (replacing an animation already there: the test motion's is the one to look at).
/// Throws InputError if `animated` names no run.
void add_test_motion_sections(LearningReport& report, const std::string& title,
    const sim::Scene& scene, const std::vector<VecX>& truth, const std::vector<LabelledRun>& runs,
    const std::string& animated);

/// The "correction" section (correction_curves_json) of `learned`, against `truth` (null when
/// unknown) with the `training` stretches (null when unknown) shaded.
void add_correction_section(LearningReport& report, const fem::MaterialModel& learned,
    const fem::MaterialModel* truth, const material::StretchRange* training);

} // namespace elastolearn::io
