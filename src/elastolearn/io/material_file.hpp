#pragma once
/// \file Learned-material files (JSON, "format": "elastolearn-material/1"): a nominal material
/// (the scene-format "material" object, io/scene_material.hpp) plus an optional correction
/// N(F̂, Ḟ̂) of paper 000 Eq. (1) — an RBF (material/rbf_correction.hpp) or a neural network
/// (material/nn_correction.hpp) — and free-form training provenance. The correction depends on
/// the principal stretches only, so a material file applies to any mesh. Layout:
/// docs/file_formats.md "Learned materials". Every error names the file and the field.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/stretch_range.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace elastolearn::io {

/// The contents of a learned-material file.
struct MaterialFile {
  nlohmann::json material; ///< the nominal model: a scene-format "material" object
  std::shared_ptr<const material::Correction> correction; ///< null, RbfCorrection or NnCorrection
  nlohmann::json training
      = nlohmann::json::object(); ///< free-form provenance (iterations, errors, options)
  /// The sorted stretches of the training motion (learn::StretchCoverage): outside them the
  /// correction extrapolates. Optional ("training_stretches"; absent in files before it).
  std::optional<material::StretchRange> training_stretches;
};

/// Read and validate a material file (format, nominal material, correction sizes and finite
/// values). Throws InputError("<path>: <field>", ...), e.g. "learned.json:
/// correction.weights[3][1]".
MaterialFile read_material_file(const std::filesystem::path& path);

/// Parse a material file already in memory; `file` names it in messages.
MaterialFile parse_material_file(const nlohmann::json& json, const std::string& file);

/// The JSON of a material file (what write_material_file writes).
/// Throws InputError if the correction is of a kind that cannot be saved.
nlohmann::json material_file_to_json(const MaterialFile& file);

/// Write atomically (temporary file + rename), after checking that the nominal material parses
/// and `training` is an object, so that what is written can be read back.
/// Throws InputError naming `path` (or the invalid field).
void write_material_file(const std::filesystem::path& path, const MaterialFile& file);

/// The model to simulate with: parse_material(file.material) with the correction attached.
/// `source` names the file in messages ("learned.json: material.young: ...").
fem::MaterialModel material_model(const MaterialFile& file, const std::string& source);

/// A correction as JSON: {"type": "rbf", ...} or {"type": "nn", ...} with every parameter
/// (doubles are written with enough digits to round-trip exactly).
/// Throws InputError for a correction kind that has no file representation.
nlohmann::json correction_to_json(const material::Correction& correction);

/// The inverse of correction_to_json; errors name `object`'s file and field.
std::shared_ptr<const material::Correction> correction_from_json(const JsonObject& object);

/// A stretch range as {"min": [s₁, s₂, s₃], "max": [...]} (the file's "training_stretches").
nlohmann::json stretch_range_to_json(const material::StretchRange& range);

/// One line for users: "rbf, 40 centres, with damping correction" or "nn, 6-6-6-3".
std::string describe_correction(const material::Correction& correction);

/// One line for users: "corotated", "corotated + correction (rbf, 40 centres)" or, with a
/// stiffness scale, "corotated, heterogeneous (stiffness x1 to x100 by region)".
std::string describe_material_model(const fem::MaterialModel& model);

/// The "material" field of a scene: an inline material object (returned as a MaterialFile
/// without correction) or a string path, relative to `base_dir`, of a material file (read and
/// returned). `scene` is the scene's root object. Throws InputError naming the scene's field
/// or the material file.
MaterialFile scene_material(const JsonObject& scene, const std::filesystem::path& base_dir);

/// The material file a scene's "material" field names (resolved against `base_dir`), or nothing
/// for an inline material object. Throws InputError naming the scene's field if the file does
/// not exist.
std::optional<std::filesystem::path> referenced_material(
    const JsonObject& scene, const std::filesystem::path& base_dir);

/// material_model(scene_material(scene, base_dir)), with errors of an inline material naming
/// the scene's field ("scene.json: material.young") and of a referenced one its file.
/// If `file` is not null it receives scene_material(scene, base_dir) (the material file is read
/// once).
fem::MaterialModel scene_material_model(
    const JsonObject& scene, const std::filesystem::path& base_dir, MaterialFile* file = nullptr);

} // namespace elastolearn::io
