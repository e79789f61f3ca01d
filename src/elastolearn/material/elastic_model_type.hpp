#pragma once
/// \file The one name table of elastic models, shared by JSON and the CLI (Ceres-style to/from
/// string pairs), and a factory for the models that need only Lamé parameters.
#include <elastolearn/material/elastic_model.hpp>

#include <array>
#include <memory>
#include <string>
#include <string_view>

namespace elastolearn::material {

enum class ElasticModelType { Corotated, StVK, NeoHookean, SplineEdited };

/// Every model type, in table order.
inline constexpr std::array<ElasticModelType, 4> all_elastic_model_types
    = { ElasticModelType::Corotated, ElasticModelType::StVK, ElasticModelType::NeoHookean,
        ElasticModelType::SplineEdited };

/// "corotated", "stvk", "neohookean", "spline_edited" (the same strings as ElasticModel::name()).
std::string to_string(ElasticModelType type);

/// Inverse of to_string (exact, case-sensitive). Throws InputError(where, ...) naming the bad
/// string and listing the valid names.
ElasticModelType elastic_model_type_from_string(
    std::string_view name, const std::string& where = "elastic model");

/// Builds a corotated, StVK or neo-Hookean model (neo-Hookean with its default inversion
/// threshold). Throws InputError for SplineEdited, which also needs a spline: construct a
/// SplineEditedModel (spline_edited.hpp) instead.
std::unique_ptr<ElasticModel> make_elastic_model(ElasticModelType type, const Lame& lame);

} // namespace elastolearn::material
