#pragma once
/// \file Whether a corrected material is stable over the stretches a motion reached (issue 19,
/// "stable corrections"): at every sampled principal stretch σ, the exact tangent of
/// P̂ + N must be positive semi-definite in the stretch block (the symmetric part of
/// ∂(P̂ + N)/∂σ: stress grows with stretch) and in the twist eigenvalues
/// (P̂ᵢ + Nᵢ − P̂ⱼ − Nⱼ)/(σᵢ − σⱼ) (shear resists). Where either fails, the material has no stable
/// equilibrium nearby, Newton's projected matrix no longer describes it, and simulations
/// diverge. The flip eigenvalues (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ) are not required: the nominal corotated
/// model itself has negative ones under compression.
#include <elastolearn/core/types.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/elastic_model.hpp>

#include <span>

namespace elastolearn::learn {

struct StabilityReport {
  /// The smallest eigenvalue over the samples, relative to the nominal model's smallest at the
  /// same sample (so −0.5: half the nominal's stiffness is removed and then as much again) [-];
  /// ≥ 0 where every sample is stable.
  double min_relative_eigenvalue = 0;
  Vec3 worst_stretches = Vec3::Ones(); ///< the sample of that eigenvalue
  long unstable_samples = 0; ///< samples with a negative eigenvalue
  long samples = 0;
  bool stable() const { return unstable_samples == 0; }
};

/// Check `correction` (null: the nominal alone) on top of `nominal` at every row of `stretches`
/// (N × 3 principal stretches, e.g. collect_stretches of a trajectory). Parallel over samples.
StabilityReport material_stability(const material::ElasticModel& nominal,
    const material::Correction* correction, ConstRef<MatX> stretches);

/// Sample stretches for the check: every row of `stretches` (sorted principal stretches of a
/// motion) raised to each power a in `amplifications`, σᵃ: the same deformations amplified in
/// log-stretch, as a larger motion of the same kind reaches them. Log-stretches keep J = 1 states
/// at J = 1 (amplifying σ − 1 instead would turn a nearly incompressible motion into large volume
/// changes, where even the truth may be unstable). Inverted samples (σ₃ ≤ 0) are kept as they
/// are. At most `max_rows` rows in all: every ⌈·⌉-th row of `stretches` is used.
MatX amplified_stretches(
    ConstRef<MatX> stretches, std::span<const double> amplifications, Eigen::Index max_rows);

} // namespace elastolearn::learn
