#pragma once
/// \file The learned-material file of a learning run (docs/learning_recipe.md): the recipe's
/// chosen candidate as a material (the fitted nominal's parameters, its correction: an RBF or the
/// network distilled from one), the stretches of the training motion, and the run's
/// provenance ("training"). What `elastolearn learn` writes and the Python `learn` returns.
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/learn/learning_recipe.hpp>

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// What the recipe decided, as JSON (the learned file's training.recipe).
nlohmann::json recipe_result_to_json(const learn::RecipeResult& result);

/// Stage 5's record in a learned file's `training` object: "network" (the distillation: kind,
/// states, errors against the teacher, times, whether it was chosen) and, when the network was
/// chosen, "teacher" (the RBF it was distilled from). Nothing if the stage did not run.
void add_network_provenance(nlohmann::json& training, const learn::RecipeResult& result);

/// The material file of `result` (learn::learn_material on `set.motions` with `options`, not
/// interrupted): the chosen candidate's nominal (the fitted parameters, unless the chosen one is
/// the given nominal) and correction, the training stretches (the first motion simulated with
/// it) and the provenance (`source`: the scene or training-set file as given; the motions,
/// options, the recipe's decisions, the loop's history; training.network: stage 5's
/// distillation, if it ran; training.teacher: the RBF a chosen network was distilled from).
MaterialFile learned_material_file(const TrainingSet& set, const std::string& source,
    const learn::RecipeResult& result, const learn::RecipeOptions& options);

} // namespace elastolearn::io
