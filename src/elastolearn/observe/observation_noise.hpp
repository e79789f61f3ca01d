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
#include <elastolearn/observe/observation.hpp>

namespace elastolearn::observe {

/// σ [m] estimated from the observation's own frames (0 with fewer than 6 frames).
double estimate_noise(const Observation& observed);

struct SmoothingResult {
  Observation smoothed;
  double kappa = 0; ///< the penalty weight chosen (0: nothing smoothed)
  double rms_change = 0; ///< √(mean over frames, vertices, coordinates of (y − x)²) [m]
};

/// The observation smoothed to the noise level `sigma` [m] (≥ 0; 0 returns it unchanged).
/// Throws InputError("noise", ...) for a negative or non-finite sigma.
SmoothingResult smooth_to_noise(const Observation& observed, double sigma);

} // namespace elastolearn::observe
