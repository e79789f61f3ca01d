#pragma once
/// \file The nominal parameters E, ν, α₀, α₁ (learn::NominalParameters) in a scene-format
/// "material" object: read as a fit's start values, written back with fitted values
/// (fit-parameters, and learn's fitted nominal).
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/material/elastic_model_type.hpp>

#include <nlohmann/json.hpp>

namespace elastolearn::io {

/// E, ν and the constant Rayleigh coefficients (0 when absent) of a "material" object, and its
/// model type. Throws InputError naming the field for a stretch-dependent coefficient (a fit moves
/// constants) or an invalid value.
learn::NominalParameters nominal_parameters_from_json(
    const JsonObject& material, material::ElasticModelType& type);

/// `material` with "young", "poisson" and, if it has a "damping" object or `with_damping`, its
/// "alpha0" and "alpha1" replaced by `parameters` (the damping's other keys kept).
nlohmann::json with_nominal_parameters(
    nlohmann::json material, const learn::NominalParameters& parameters, bool with_damping);

/// {"young", "poisson", "alpha0", "alpha1"}.
nlohmann::json to_json(const learn::NominalParameters& parameters);

} // namespace elastolearn::io
