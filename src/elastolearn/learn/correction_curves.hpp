#pragma once
/// \file A material's correction sampled along paths of principal stretches, for plots: the
/// stress a model adds to a reference nominal model along uniaxial stretch and along the paper's
/// deformation scale ‖F̂ − (1, 1, 1)‖ (paper 000 Fig. 6), and its Rayleigh stiffness-damping
/// coefficient α₁ + Δα₁ along the largest stretch (Eq. 13). Applied to a learned material the
/// stress difference is its correction N(F̂, 0); applied to a ground-truth material it is the
/// correction the learning should find (the truth's stress minus the nominal's).
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/material/stretch_range.hpp>

#include <string>
#include <vector>

namespace elastolearn::learn {

/// Sorted principal stretches (s₁ ≥ s₂ ≥ s₃) at abscissae `x`, a curve's samples.
struct StretchPath {
  std::string label; ///< e.g. "uniaxial tension"
  std::vector<double> x; ///< the plot's abscissa at each sample
  std::vector<Vec3> stretches; ///< sorted descending
};

/// σ = (s, 1, 1), sorted, for `samples` values of s evenly from `low` to `high` (x = s).
/// Throws InputError("stretch path", ...) unless 0 < low < high and samples ≥ 2.
StretchPath uniaxial_path(double low, double high, int samples);

/// Along the deformation scale d = ‖F̂ − (1, 1, 1)‖ from 0 to `max_scale` (x = d), one path per
/// direction: uniaxial tension and compression, equibiaxial tension and compression, volumetric
/// expansion and compression (F̂ = (1, 1, 1) + d·u with u the unit direction, sorted).
/// Throws InputError("stretch path", ...) unless 0 < max_scale < 1 (no stretch reaches 0) and
/// samples ≥ 2.
std::vector<StretchPath> deformation_scale_paths(double max_scale, int samples);

/// Along the largest stretch s₁ = s from `low` to `high` (x = s): uniaxial σ = (s, 1, 1) above
/// 1 and uniform compression σ = (s, s, s) below, so that s is the largest stretch everywhere
/// (what a stretch-dependent Rayleigh damping is a function of). Throws as uniaxial_path.
StretchPath largest_stretch_path(double low, double high, int samples);

/// P̂_model(σ) + N_model(σ, 0) − P̂_reference(σ) [Pa] at each sample: the stress `model` adds to
/// the reference's elastic model at rest rates. `model.elastic` and `reference` are required.
std::vector<Vec3> stress_difference(const StretchPath& path, const fem::MaterialModel& model,
    const material::ElasticModel& reference);

/// α₁(s₁) + Δα₁(σ) [s] at each sample, kept ≥ 0 as the simulation does
/// (material::corrected_stiffness_damping); 0 everywhere for a model without damping.
std::vector<double> stiffness_damping(const StretchPath& path, const fem::MaterialModel& model);

/// Whether each sample lies in `range` (StretchRange::contains with tolerance 0); all false for
/// an empty range.
std::vector<bool> inside(const StretchPath& path, const material::StretchRange& range);

} // namespace elastolearn::learn
