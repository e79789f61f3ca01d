#include <elastolearn/springs/training_data.hpp>

#include <elastolearn/core/error.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::springs {

std::string_view to_string(SamplingKind kind) {
  return kind == SamplingKind::trajectories ? "trajectories" : "phase-grid";
}

SamplingKind sampling_kind_from_string(const std::string& name, const std::string& where) {
  if (name == "trajectories")
    return SamplingKind::trajectories;
  if (name == "phase-grid")
    return SamplingKind::phase_grid;
  throw InputError(
      where, "unknown sampling '" + name + "' (expected one of: trajectories, phase-grid)");
}

namespace {
/// Largest tangent stiffness of the law over the sampled elongations (for stability and scales).
double max_stiffness(const TrainingOptions& o) {
  double kmax = 0.0;
  for (double e : o.elongations)
    kmax = std::max(
        { kmax, -o.law.force_derivative_e(e, 0.0), -o.law.force_derivative_e(0.0, 0.0) });
  return kmax;
}
} // namespace

void TrainingOptions::validate() const {
  law.validate();
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("training options.dt", "must be > 0, got " + std::to_string(dt));
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw InputError("training options.mass", "must be > 0, got " + std::to_string(mass));
  if (elongations.empty())
    throw InputError("training options.elongations", "needs at least one value");
  for (double e : elongations)
    if (!std::isfinite(e))
      throw InputError("training options.elongations", "non-finite value");
  if (steps < 2)
    throw InputError("training options.steps", "must be >= 2, got " + std::to_string(steps));
  if (!(max_speed >= 0.0))
    throw InputError("training options.max_speed", "must be >= 0");
  if (sampling == SamplingKind::trajectories) {
    const double kappa = max_stiffness(*this) * dt * dt / mass;
    if (kappa >= 4.0)
      throw InputError("training options.dt",
          "semi-implicit Euler trajectories diverge for k*dt^2/m = " + std::to_string(kappa)
              + " >= 4; use phase-grid sampling or a smaller dt");
  }
  const double lo = *std::min_element(elongations.begin(), elongations.end());
  const double hi = *std::max_element(elongations.begin(), elongations.end());
  if (sampling == SamplingKind::phase_grid && !(hi > lo))
    throw InputError(
        "training options.elongations", "phase-grid sampling needs a range (min < max)");
}

Vec2 semi_implicit_step_1d(const SpringLaw& law, double dt, double mass, double e, double v) {
  const double dv = dt * law.force(e, v) / mass; // Eq. (1)
  return { dt * (v + dv), dv }; // Eq. (2): Δe = dt v(t+dt)
}

TrainingSet generate_training_set(const TrainingOptions& options) {
  options.validate();
  TrainingSet set;
  set.dt = options.dt;
  set.mass = options.mass;
  set.law = options.law;
  std::vector<Vec2> in, out;
  if (options.sampling == SamplingKind::trajectories) {
    for (double d : options.elongations) {
      double e = d, v = 0.0;
      for (int s = 0; s < options.steps; ++s) {
        const Vec2 delta = semi_implicit_step_1d(options.law, options.dt, options.mass, e, v);
        in.emplace_back(e, v);
        out.push_back(delta);
        e += delta[0];
        v += delta[1];
      }
    }
  } else {
    const double lo = *std::min_element(options.elongations.begin(), options.elongations.end());
    const double hi = *std::max_element(options.elongations.begin(), options.elongations.end());
    const double amplitude = std::max(std::abs(lo), std::abs(hi));
    const double vmax = options.max_speed > 0.0
        ? options.max_speed
        : amplitude * std::sqrt(std::max(max_stiffness(options), 1e-12) / options.mass);
    const int n = options.steps;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double e = lo + (hi - lo) * i / (n - 1);
        const double v = -vmax + 2.0 * vmax * j / (n - 1);
        in.emplace_back(e, v);
        out.push_back(semi_implicit_step_1d(options.law, options.dt, options.mass, e, v));
      }
  }
  set.inputs.resize(static_cast<Eigen::Index>(in.size()), 2);
  set.outputs.resize(static_cast<Eigen::Index>(out.size()), 2);
  for (std::size_t r = 0; r < in.size(); ++r) {
    set.inputs.row(static_cast<Eigen::Index>(r)) = in[r].transpose();
    set.outputs.row(static_cast<Eigen::Index>(r)) = out[r].transpose();
  }
  return set;
}

} // namespace elastolearn::springs
