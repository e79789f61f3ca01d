#include <elastolearn/learn/candidate_choice.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastolearn::learn {

std::string to_string(CandidateKind kind) {
  switch (kind) {
  case CandidateKind::Nominal:
    return "nominal";
  case CandidateKind::FittedNominal:
    return "fitted nominal";
  case CandidateKind::Loop:
    return "loop";
  case CandidateKind::Network:
    return "network";
  case CandidateKind::ForwardFit:
    return "forward fit";
  }
  return "?";
}

namespace {

/// gain / (2σ‖c − r‖), ±∞ (0 for no gain) where the spread vanishes.
double in_noise_deviations(double gain, const VecX& r, const VecX& c, double sigma) {
  const double spread = 2 * sigma * (c - r).norm();
  if (spread > 0)
    return gain / spread;
  if (gain == 0)
    return 0;
  return gain > 0 ? std::numeric_limits<double>::infinity()
                  : -std::numeric_limits<double>::infinity();
}

} // namespace

double significance_threshold(int compared) {
  // Φ⁻¹(1 − p) by bisection on Φ(−z) = ½ erfc(z/√2), decreasing in z: 60 halvings of [0, 40]
  // leave 4e-17, below what the z's own rounding resolves.
  const double p = 0.5 * std::erfc(kSignificance / std::sqrt(2.0)) / std::max(compared, 1);
  double lo = 0, hi = 40;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double paired_significance(const VecX& r, const VecX& c, const VecX& o, double sigma) {
  return in_noise_deviations((r - o).squaredNorm() - (c - o).squaredNorm(), r, c, sigma);
}

void compare_with_reference(std::vector<Candidate>& candidates, size_t i, int reference,
    const ComparedData& validation, const ComparedData& training, double sigma, double threshold) {
  Candidate& c = candidates[i];
  const auto r = static_cast<size_t>(reference);
  const VecX &rv = validation.predictions[r], &cv = validation.predictions[i];
  c.significance = paired_significance(rv, cv, validation.observed, sigma);
  c.resolution = in_noise_deviations((cv - rv).squaredNorm(), rv, cv, sigma);
  c.training_significance = std::numeric_limits<double>::quiet_NaN();
  if (std::max(i, r) < training.predictions.size() && training.predictions[i].size() > 0
      && training.predictions[r].size() > 0) {
    const VecX &rt = training.predictions[r], &ct = training.predictions[i];
    const VecX& o = training.observed;
    const double charge = c.unknowns * sigma * sigma;
    c.training_significance = in_noise_deviations(
        (rt - o).squaredNorm() - (ct - o).squaredNorm() - charge, rt, ct, sigma);
  }
  // The held-out data alone decide: the training frames cannot see how a candidate forecasts.
  c.required_significance = threshold;
  c.beats_reference = c.resolution >= threshold && c.significance >= threshold;
}

bool network_replaces_teacher(
    const Candidate& network, const Candidate& teacher, bool has_reference) {
  const bool as_good = network.gain_over_teacher > -kSignificance
      || network.validation.rms <= (1 + kNetworkTolerance) * teacher.validation.rms;
  return network.kind == CandidateKind::Network && network.eligible() && teacher.completed
      && (!has_reference || network.beats_reference) && as_good;
}

int choose_candidate(std::vector<Candidate>& candidates, const ComparedData& validation,
    const ComparedData& training, int reference, double sigma) {
  int chosen = -1;
  const Candidate* ref = reference >= 0 ? &candidates[static_cast<size_t>(reference)] : nullptr;
  if (ref && !ref->completed)
    ref = nullptr;
  int corrections = 0; // what may replace the reference, and so what noise may pass
  for (size_t i = 0; i < candidates.size(); ++i)
    corrections += candidates[i].completed && static_cast<int>(i) != reference
        && candidates[i].kind != CandidateKind::Nominal;
  const double threshold = significance_threshold(corrections);
  for (size_t i = 0; i < candidates.size(); ++i) {
    Candidate& c = candidates[i];
    if (!c.completed)
      continue;
    const bool is_reference = !ref || static_cast<int>(i) == reference;
    if (!is_reference)
      compare_with_reference(candidates, i, reference, validation, training, sigma, threshold);
    // The given nominal beside a fitted one is reported, not chosen: it is a guess the data did
    // not inform, and the result is promised never worse than the fit. It can beat the fit on
    // the held-out tail where the tail is unlike the motion (a decayed tail, whose small
    // stretches see a stretch-dependent damping at its small-stretch value).
    if (!c.eligible() || (!is_reference && c.kind == CandidateKind::Nominal))
      continue;
    if ((is_reference || c.beats_reference)
        && (chosen < 0
            || c.validation.rms < candidates[static_cast<size_t>(chosen)].validation.rms))
      chosen = static_cast<int>(i);
  }
  return chosen;
}

int choose_checked_candidate(std::vector<Candidate>& candidates, const ComparedData& validation,
    const ComparedData& training, int reference, double sigma,
    const std::function<void(Candidate&)>& check_larger_motion) {
  for (;;) {
    const int chosen = choose_candidate(candidates, validation, training, reference, sigma);
    if (chosen < 0)
      return chosen;
    Candidate& c = candidates[static_cast<size_t>(chosen)];
    if (!c.correction || c.larger_motion.checked)
      return chosen;
    check_larger_motion(c); // if it fails, the next choice is another candidate
    c.larger_motion.checked = true;
  }
}

} // namespace elastolearn::learn
