#pragma once
/// \file The noise of observed positions and its removal in time (issue 19, "noisy captures").
///
/// Estimate: for independent noise of standard deviation σ per coordinate, the k-th finite
/// difference Δᵏx of a coordinate's series has variance C(2k, k) σ² (6, 20, 70 for k = 2, 3, 4),
/// while a smooth motion's own differences shrink as dtᵏ. The robust estimate per order is
/// 1.4826 · median|Δᵏx| / √C(2k, k) over every observed coordinate and frame (the median ignores
/// the few frames of an impact or a release); the smallest over k = 2, 3, 4 is reported, since
/// motion can only add to each.
///
/// Smoothing: per coordinate, the Whittaker–Henderson smoother y = argmin ‖y − x‖² + κ‖Δ³y‖²
/// (a penalty on jerk, so that constant acceleration, e.g. free fall, passes unchanged), with one
/// κ for the whole observation chosen by Morozov's discrepancy principle: the RMS change
/// ‖y − x‖/√N equals σ. The learning loop differentiates positions twice (its accelerations);
/// it must see y, never raw x (docs/learning_recipe.md).
///
/// Lost entries (Observation::valid): the estimate uses only differences whose frames were all
/// seen; the smoother's data term is weighted by the mask, y = argmin (y − x)ᵀW(y − x) + κ‖Δ³y‖²
/// with W = diag(valid), so it fills each gap with its smooth continuation and never reads a
/// lost position; N counts seen entries only.
#include <elastolearn/observe/observation.hpp>

namespace elastolearn::observe {

/// σ [m] estimated from the observation's own frames (0 with fewer than 6 frames, or when no
/// point was seen in 3 consecutive frames; orders whose k + 1 frames were never all seen are
/// skipped).
double estimate_noise(const Observation& observed);

struct SmoothingResult {
  /// The smoothed positions; lost entries hold the smoother's fill (finite), and the mask is
  /// kept, so consumers still know which entries were measured.
  Observation smoothed;
  double kappa = 0; ///< the penalty weight chosen (0: nothing smoothed)
  /// √(mean over seen frames, vertices, coordinates of (y − x)²) [m]
  double rms_change = 0;
};

/// The observation smoothed to the noise level `sigma` [m] (≥ 0; 0 leaves the seen entries
/// unchanged and only fills the lost ones, as fill_lost_entries). A point seen in fewer than 3
/// frames is not smoothed (a quadratic through its frames is not unique), only filled.
/// Throws InputError("noise", ...) for a negative or non-finite sigma.
SmoothingResult smooth_to_noise(const Observation& observed, double sigma);

/// The observation with every lost entry replaced by the smoothest continuation of the same
/// point's seen entries: per point and coordinate, the lost values minimise ‖Δ^q y‖² with the
/// seen ones fixed (q = 3, the smoother's κ → 0 limit: quintic-like through a gap, quadratic
/// beyond the first or last seen frame; q = 1 or 2 for a point seen in only 1 or 2 frames:
/// constant or linear). Seen entries and the mask are copied unchanged; the positions of a point
/// never seen are left as they are. Depends only on the seen entries.
Observation fill_lost_entries(const Observation& observed);

} // namespace elastolearn::observe
