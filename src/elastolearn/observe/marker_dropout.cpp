#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/observe/marker_dropout.hpp>

#include <cmath>
#include <limits>
#include <random>

namespace elastolearn::observe {

void drop_markers(Observation& observed, double fraction, double mean_burst, std::uint64_t seed) {
  if (!(fraction >= 0 && fraction < 1))
    throw InputError("dropout", "must be a fraction in [0, 1), got " + to_text_exact(fraction));
  if (!(mean_burst >= 1 && std::isfinite(mean_burst)))
    throw InputError(
        "dropout burst", "must be a mean length ≥ 1 frame, got " + to_text_exact(mean_burst));
  if (fraction == 0)
    return;
  const int frames = observed.num_frames(), k = observed.num_observed();
  if (observed.valid.size() == 0)
    observed.valid = ValidityMask::Ones(frames, k);
  double lose = fraction / ((1 - fraction) * mean_burst); // p: seen → lost
  double recover = 1 / mean_burst; // q: lost → seen
  if (lose > 1) {
    lose = 1;
    recover = (1 - fraction) / fraction;
  }
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  ValidityMask dropped = observed.valid;
  for (int j = 0; j < k; ++j) {
    bool lost = uniform(random) < fraction;
    for (int t = 0; t < frames; ++t) {
      if (t > 0)
        lost = lost ? !(uniform(random) < recover) : uniform(random) < lose;
      if (lost)
        dropped(t, j) = 0;
    }
  }
  if ((dropped == 0).all()) {
    // Keep the first entry (frame-major) that was seen before, so that the observation keeps one.
    for (Eigen::Index i = 0; i < dropped.size(); ++i)
      if (observed.valid.data()[i] != 0) {
        dropped.data()[i] = 1;
        break;
      }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int t = 0; t < frames; ++t)
    for (int j = 0; j < k; ++j)
      if (!dropped(t, j))
        observed.positions[static_cast<size_t>(t)].row(j).setConstant(nan);
  observed.valid = std::move(dropped);
}

} // namespace elastolearn::observe
