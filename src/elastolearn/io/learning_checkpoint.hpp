#pragma once
/// \file Checkpoints of learning (JSON, "format": "elastolearn-learning-checkpoint/3"; versions
/// 1 and 2, with flat iteration records, are still read): the
/// recipe's parameter fit and the complete learn::LearningState after an iteration — corrections
/// written with every digit (correction_to_json), so a resumed run continues bit-for-bit — plus the
/// inputs it belongs to, so that `learn --resume` refuses a checkpoint of another scene or
/// observation file.
#include <elastolearn/learn/learning_recipe.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace elastolearn::io {

/// What a checkpoint must match to be resumed: the input files and the options.
struct LearningInputs {
  std::string scene; ///< scene file, as given
  std::string observations; ///< observation file, as given
  nlohmann::json options; ///< the options (recipe_options_to_json)
};

/// Write atomically. Throws InputError naming the path.
void write_learning_checkpoint(const std::filesystem::path& path, const LearningInputs& inputs,
    const learn::RecipeResume& resume);

/// Read a checkpoint and check it against `inputs` (same scene and observation paths, same
/// options). Throws InputError naming the file and the field that differs or is invalid.
learn::RecipeResume read_learning_checkpoint(
    const std::filesystem::path& path, const LearningInputs& inputs);

/// The checkpoint file of a run that writes the learned material to `output`: `checkpoint` if
/// not empty, else OUTPUT.checkpoint.json (`learn --checkpoint`'s default).
std::filesystem::path learning_checkpoint_path(
    const std::filesystem::path& output, const std::filesystem::path& checkpoint);

/// read_learning_checkpoint for a resumed run (`option` names the request to resume, e.g.
/// "--resume"): throws InputError naming `path` when there is no file there ("no checkpoint to
/// resume from (run without --resume first)").
learn::RecipeResume resume_learning_checkpoint(
    const std::filesystem::path& path, const LearningInputs& inputs, const std::string& option);

/// One step's record as JSON (also used in reports and in the learned material's "training"
/// provenance): {"iteration", "kind": "loop" | "forward_fit", "forward": {"status", "error" when
/// completed, "message" otherwise}, then for a loop iteration "next": "space_time" |
/// "damped_update" | "end" (and "stages" with space_time), for a forward-fit step "accepted" and
/// "centres"; "seconds": {"forward", the stages' times, "total"}} (docs/file_formats.md).
nlohmann::json iteration_record_to_json(const learn::IterationRecord& record);

/// The options that determine the result, as JSON.
nlohmann::json learning_options_to_json(const learn::LearningOptions& options);
/// The recipe's options (its loop's with learning_options_to_json), as JSON.
nlohmann::json recipe_options_to_json(const learn::RecipeOptions& options);

} // namespace elastolearn::io
