#pragma once
/// \file The learned-material file of a learning run (docs/learning_recipe.md): the recipe's
/// chosen candidate as a material (the fitted nominal's parameters, its correction, optionally
/// distilled into the network correction), the stretches of the training motion, and the run's
/// provenance ("training"). What `elastolearn learn` writes and the Python `learn` returns.
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/nn_distillation.hpp>

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// Distillation of the chosen RBF into the network correction (docs/learning.md, "Neural-network
/// correction"): states of the first training scene at several motion amplitudes.
struct NetworkDistillation {
  bool enabled = false;
  /// "auto": the energy network for an RBF with energy kernels, else the stress network;
  /// "energy" or "stress".
  std::string kind = "auto";
  std::vector<double> motion_scales { 0.5, 1.0, 2.0 };
  learn::DistillationSampleOptions samples;
  learn::NnDistillationOptions training;
};

/// What the recipe decided, as JSON (the learned file's training.recipe).
nlohmann::json recipe_result_to_json(const learn::RecipeResult& result);

/// The material file of `result` (learn::learn_material on `set.motions` with `options`, not
/// interrupted): the chosen candidate's nominal (the fitted parameters, unless the chosen one is
/// the given nominal) and correction, the training stretches (the first motion simulated with
/// it) and the provenance (`source`: the scene or training-set file as given; the motions,
/// options, the recipe's decisions, the loop's history). With `network.enabled` and a
/// correction, the correction is the network distilled from it and the RBF goes to
/// training.teacher. `message` receives one line per distillation event (may be empty).
/// Throws InputError for invalid distillation options.
MaterialFile learned_material_file(const TrainingSet& set, const std::string& source,
    const learn::RecipeResult& result, const learn::RecipeOptions& options,
    const NetworkDistillation& network = {},
    const std::function<void(const std::string&)>& message = {});

} // namespace elastolearn::io
