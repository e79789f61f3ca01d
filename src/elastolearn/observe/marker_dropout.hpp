#pragma once
/// \file Simulated lost markers (issue 20): occlusion bursts, each observed point lost for runs
/// of consecutive frames, as a camera loses a marker behind the object or a depth camera a
/// surface point.
#include <elastolearn/observe/observation.hpp>

#include <cstdint>

namespace elastolearn::observe {

/// Mark runs of frames of each point as lost (Observation::valid) and set their positions to
/// NaN, a depth camera's "no value"; entries already lost stay lost.
///
/// Each point independently follows a two-state Markov chain over its frames (a Gilbert
/// channel): a seen frame is followed by a lost one with probability p, a lost frame by a seen
/// one with probability q = 1/L, so bursts of loss have geometric lengths of mean L frames and
/// the stationary lost fraction is p/(p + q) = `fraction` (p = fraction / ((1 − fraction) L));
/// where that p would exceed 1 (fraction > L/(L + 1)), p = 1 and L = fraction/(1 − fraction).
/// Frame 0 draws from the stationary distribution. Draws: std::mt19937_64(seed), point by point,
/// frame by frame, one uniform number each, so the result depends only on the inputs and seed.
/// fraction = 0 changes nothing. A point may end up never seen (it is then ignored); at least
/// one entry stays seen (if every entry would be lost, the first one seen before is kept).
/// \param fraction   the expected lost fraction of (frame, point) entries, in [0, 1)
/// \param mean_burst L, the mean length of a burst of loss [frames], ≥ 1
/// Throws InputError("dropout", ...) / ("dropout burst", ...) for values out of range.
void drop_markers(Observation& observed, double fraction, double mean_burst, std::uint64_t seed);

} // namespace elastolearn::observe
