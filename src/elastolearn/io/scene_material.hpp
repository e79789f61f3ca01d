#pragma once
/// \file The "material" object of scene files (and of learned-material files):
///   {"model": "corotated"|"stvk"|"neohookean"|"spline_edited", "young": Pa, "poisson": ν,
///    "density": kg/m³,
///    "edit": {"base": "neohookean"|"corotated", "region": "tension"|"compression",
///             "stretches": [...], "scales": [...]}            (spline_edited only)
///    "damping": {"alpha0": 1/s, "alpha1": s, "tangent": "flip-free" (default) | "exact"}
///            where either coefficient may instead be a function of the largest stretch σ₁:
///            {"stretches": [...], "values": [...]} (a monotone spline) or
///            {"polynomial": [c₀, c₁, ...]} (Σ cₖ (σ₁ − 1)ᵏ, clamped at 0)}
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/io/json_fields.hpp>

#include <nlohmann/json.hpp>

namespace elastolearn::io {

/// Build the material model; errors name the file and field.
fem::MaterialModel parse_material(const JsonObject& object);

} // namespace elastolearn::io
