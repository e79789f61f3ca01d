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
#include <string>

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

/// The smallest eigenvalue (stretch block or twist) of nominal + `correction` (null: the
/// nominal alone) at principal stretches σ, relative to the nominal's smallest there: < 0 where
/// the corrected material is unstable.
double relative_stability(const material::ElasticModel& nominal,
    const material::Correction* correction, const Vec3& stretches);

/// Check `correction` (null: the nominal alone) on top of `nominal` at every row of `stretches`
/// (N × 3 principal stretches, e.g. collect_stretches of a trajectory). Parallel over samples.
StabilityReport material_stability(const material::ElasticModel& nominal,
    const material::Correction* correction, ConstRef<MatX> stretches);

/// "unstable at N of M <what> (stiffness s × the nominal's at σ = (σ₁, σ₂, σ₃))": a report's
/// count and its least stable sample, for messages.
std::string describe_unstable(const StabilityReport& report, const std::string& what);

/// Sample stretches for the check: every row of `stretches` (sorted principal stretches of a
/// motion) raised to each power a in `amplifications`, σᵃ: the same deformations amplified in
/// log-stretch, as a larger motion of the same kind reaches them. Log-stretches keep J = 1 states
/// at J = 1 (amplifying σ − 1 instead would turn a nearly incompressible motion into large volume
/// changes, where even the truth may be unstable). Inverted samples (σ₃ ≤ 0) are kept as they
/// are. At most `max_rows` rows in all: every ⌈·⌉-th row of `stretches` is used.
MatX amplified_stretches(
    ConstRef<MatX> stretches, std::span<const double> amplifications, Eigen::Index max_rows);

/// The recipe's reachable stretches (the loop, the forward fit and the validation choice): the
/// nominal's stress up to twice the data's largest (a user's next motion of another kind at
/// twice the load), on a grid a third as fine as the kernel smoothing of the recipe's RBF (0.03:
/// a kernel correction varies on that scale).
inline constexpr double kReachableStress = 2;
inline constexpr double kReachableAmplification = 1.25; ///< as the loop's amplified stretches
inline constexpr double kReachableSpacing = 0.01;
inline constexpr int kReachableMinPoints = 9; ///< per axis, however small the data's range
inline constexpr int kReachableMaxPoints = 25; ///< per axis: 2925 sorted samples at most

/// Where a motion of another kind may go: the data of one motion constrain a correction only
/// along the stretch combinations that motion visits (a droop's uniaxial states), yet a kernel or
/// network correction takes values everywhere in between, and a swing or a twist reaches other
/// combinations at the same stress. The samples: a grid of sorted principal stretches
/// (σ₁ ≥ σ₂ ≥ σ₃) with spacing at most `spacing` (kReachableMinPoints to kReachableMaxPoints per
/// axis) over [a, b] = [min, max] of `stretches` raised to `amplification` (beyond the data, as
/// amplified_stretches), kept where the nominal's principal stress ‖P̂(σ)‖ is at most
/// `stress_factor` times its largest over `stretches` (states the nominal reaches under loads of
/// the data's order) and the volume ratio J = σ₁σ₂σ₃ is within the data's range of J raised to
/// `amplification`, widened by one grid step. Motions of other kinds change an element's shape
/// differently, its volume no more than loads of the same order do: without the J bound, data
/// that reach a large stress in shear (the turtle's droop, s₁ 1.32) admit equibiaxial states
/// of 59 % more volume, far from any motion of a nearly incompressible solid, where a correction
/// is then required to be stable. Inverted samples (σ₃ ≤ 0) are skipped; empty if no sample is
/// left. Needs spacing > 0, amplification ≥ 1 and stress_factor > 0. The defaults are the
/// recipe's.
MatX reachable_stretches(const material::ElasticModel& nominal, ConstRef<MatX> stretches,
    double amplification = kReachableAmplification, double stress_factor = kReachableStress,
    double spacing = kReachableSpacing);

} // namespace elastolearn::learn
