#include <elastolearn/core/error.hpp>
#include <elastolearn/core/interrupt.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/levenberg_marquardt.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/spline_edited.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace elastolearn::learn {

namespace {

constexpr double kPoissonMax = 0.49; ///< upper end of the fitted ν range (0, 0.49)
constexpr std::array<const char*, 4> kParameterNames = { "young", "poisson", "alpha0", "alpha1" };

/// The change of variables u ↔ p that keeps every trial physically valid.
struct ParameterTransform {
  double floor0 = 0, floor1 = 0;

  double to_u(FitParameter which, const NominalParameters& p) const {
    switch (which) {
    case FitParameter::Young:
      return std::log(p.young);
    case FitParameter::Poisson: {
      const double s = p.poisson / kPoissonMax;
      return std::log(s / (1 - s));
    }
    case FitParameter::Alpha0:
      return std::log(p.alpha0 + floor0);
    case FitParameter::Alpha1:
      return std::log(p.alpha1 + floor1);
    }
    return 0;
  }
  /// The least u of a parameter (a damping's u at which it is 0), −∞ where there is none.
  double lower_u(FitParameter which) const {
    switch (which) {
    case FitParameter::Alpha0:
      return std::log(floor0);
    case FitParameter::Alpha1:
      return std::log(floor1);
    default:
      return -std::numeric_limits<double>::infinity();
    }
  }
  void set(FitParameter which, double u, NominalParameters& p) const {
    switch (which) {
    case FitParameter::Young:
      p.young = std::exp(u);
      break;
    case FitParameter::Poisson:
      p.poisson = kPoissonMax / (1 + std::exp(-u));
      break;
    case FitParameter::Alpha0:
      p.alpha0 = damping(u, floor0);
      break;
    case FitParameter::Alpha1:
      p.alpha1 = damping(u, floor1);
      break;
    }
  }
  /// eᵘ − floor, exactly 0 at and below the bound: a step onto it lands within a few ulps of
  /// log(floor), whose round-off (~10⁻¹⁸ 1/s) must not count as a damping (the recipe learns Δα₀
  /// only for a fitted α₀ > 0).
  static double damping(double u, double floor) {
    const double alpha = std::exp(u) - floor;
    return alpha > 1e-9 * floor ? alpha : 0.0;
  }
};

/// Forward simulations of every motion compared with its observation.
struct Evaluation {
  bool completed = false;
  /// Not completed because the initial static solve failed: no equilibrium was found under the
  /// motion's initial load with these parameters (ParameterFitReport::unheld_loads).
  bool load_not_held = false;
  std::string message; ///< the simulation's reason when not completed
  /// x_sim − x_obs at the observed vertices, motion after motion, each frame-major,
  /// Σ (frames+1)·k·3
  VecX residual;
  double cost = std::numeric_limits<double>::infinity(); ///< ‖residual‖²
  double max_error = 0; ///< max over (motion, frame, vertex) of the error norm [m]

  double rms(int samples) const { return std::sqrt(cost / samples); }
};

/// One motion of the fit: its scene, observation and the steps simulated.
struct FitMotion {
  const sim::Scene* scene = nullptr;
  const observe::Observation* observed = nullptr;
  int frames = 0;
  Eigen::Index samples() const {
    return static_cast<Eigen::Index>(frames + 1) * observed->num_observed();
  }
};

Evaluation evaluate(std::span<const FitMotion> motions, material::ElasticModelType type,
    const NominalParameters& parameters) {
  Eigen::Index length = 0;
  for (const FitMotion& m : motions)
    length += 3 * m.samples();
  Evaluation e;
  e.residual.setZero(length);
  double max_sq = 0;
  Eigen::Index offset = 0;
  for (const FitMotion& m : motions) {
    sim::Scene scene = scene_with_parameters(*m.scene, type, parameters);
    scene.frames = m.frames;
    const observe::Observation& obs = *m.observed;
    const int k = obs.num_observed();
    const auto sink = [&](int frame, double, const VecX& x, const VecX&) {
      const Positions& observed = obs.positions[static_cast<size_t>(frame)];
      for (int j = 0; j < k; ++j) {
        if (!obs.is_valid(frame, j))
          continue; // a lost entry: its residual stays 0
        const Vec3 d = x.segment<3>(3 * obs.vertex_ids[static_cast<size_t>(j)])
            - observed.row(j).transpose();
        e.residual.segment<3>(offset + (static_cast<Eigen::Index>(frame) * k + j) * 3) = d;
        max_sq = std::max(max_sq, d.squaredNorm());
      }
    };
    const sim::SimulationReport report = sim::run_simulation(scene, sink);
    if (!report.completed) {
      e.load_not_held = !report.initial.converged;
      e.message = report.message;
      return e;
    }
    offset += 3 * m.samples();
  }
  e.completed = e.residual.allFinite();
  if (!e.completed) {
    e.message = "non-finite positions";
    return e;
  }
  e.cost = e.residual.squaredNorm();
  e.max_error = std::sqrt(max_sq);
  return e;
}

std::string describe(const NominalParameters& p) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "E %.5g Pa, nu %.4f, alpha0 %.4g 1/s, alpha1 %.4g s", p.young,
      p.poisson, p.alpha0, p.alpha1);
  return buf;
}

std::string describe(const ParameterFitIteration& it) {
  char buf[320];
  std::snprintf(buf, sizeof buf,
      "iteration %d: rms %.4g m, max %.4g m | %s | lambda %.2g, %d rejected | %.1f s", it.iteration,
      it.rms_error, it.max_error, describe(it.parameters).c_str(), it.lambda, it.rejected_steps,
      it.seconds);
  return buf;
}

void check_start(const NominalParameters& p, const std::vector<FitParameter>& fitted) {
  if (!(p.young > 0 && std::isfinite(p.young)))
    throw InputError(
        "young", "start value must be positive and finite, got " + std::to_string(p.young));
  if (!(p.poisson > -1 && p.poisson < 0.5))
    throw InputError(
        "poisson", "start value must be in (-1, 0.5), got " + std::to_string(p.poisson));
  if (!(p.alpha0 >= 0 && std::isfinite(p.alpha0)))
    throw InputError(
        "alpha0", "start value must be >= 0 and finite, got " + std::to_string(p.alpha0));
  if (!(p.alpha1 >= 0 && std::isfinite(p.alpha1)))
    throw InputError(
        "alpha1", "start value must be >= 0 and finite, got " + std::to_string(p.alpha1));
  const bool fits_poisson
      = std::find(fitted.begin(), fitted.end(), FitParameter::Poisson) != fitted.end();
  if (fits_poisson && !(p.poisson > 0 && p.poisson < kPoissonMax))
    throw InputError("poisson",
        "start value " + std::to_string(p.poisson)
            + " is outside the fitted range (0, 0.49): start inside it or do not fit poisson");
}

} // namespace

std::string to_string(FitParameter parameter) {
  return kParameterNames[static_cast<size_t>(parameter)];
}

FitParameter fit_parameter_from_string(std::string_view name, const std::string& where) {
  for (size_t i = 0; i < kParameterNames.size(); ++i)
    if (name == kParameterNames[i])
      return static_cast<FitParameter>(i);
  throw InputError(where,
      "unknown parameter '" + std::string(name) + "' (valid: young, poisson, alpha0, alpha1)");
}

std::vector<FitParameter> fit_parameters_from_string(
    std::string_view list, const std::string& where) {
  std::vector<FitParameter> result;
  size_t begin = 0;
  while (begin <= list.size()) {
    size_t end = list.find(',', begin);
    if (end == std::string_view::npos)
      end = list.size();
    std::string_view token = list.substr(begin, end - begin);
    while (!token.empty() && token.front() == ' ')
      token.remove_prefix(1);
    while (!token.empty() && token.back() == ' ')
      token.remove_suffix(1);
    if (token.empty())
      throw InputError(where, "empty parameter name in '" + std::string(list) + "'");
    const FitParameter p = fit_parameter_from_string(token, where);
    if (std::find(result.begin(), result.end(), p) != result.end())
      throw InputError(where, "parameter '" + std::string(token) + "' is listed twice");
    result.push_back(p);
    begin = end + 1;
  }
  return result;
}

std::string to_string(FitStop stop) {
  switch (stop) {
  case FitStop::Converged:
    return "converged";
  case FitStop::MaxIterations:
    return "max_iterations";
  case FitStop::NoImprovingStep:
    return "no_improving_step";
  case FitStop::StartDiverged:
    return "start_diverged";
  case FitStop::Interrupted:
    return "interrupted";
  }
  return "unknown";
}

sim::Scene scene_with_parameters(
    const sim::Scene& scene, material::ElasticModelType type, const NominalParameters& parameters) {
  const material::Lame lame
      = material::Lame::from_young_poisson(parameters.young, parameters.poisson);
  sim::Scene result = scene;
  if (type == material::ElasticModelType::SplineEdited) {
    const auto* edited
        = dynamic_cast<const material::SplineEditedModel*>(scene.material.elastic.get());
    if (!edited)
      throw InputError("material.model",
          "spline_edited parameters need a scene whose material is spline-edited (it holds the "
          "spline)");
    result.material.elastic = std::make_shared<material::SplineEditedModel>(
        edited->base_type(), lame, edited->region(), edited->spline());
  } else {
    result.material.elastic = material::make_elastic_model(type, lame);
  }
  auto damping = std::make_shared<material::RayleighDamping>(parameters.alpha0, parameters.alpha1);
  damping->set_tangent(material::damping_tangent_of(scene.material.damping.get()));
  result.material.damping = std::move(damping);
  return result;
}

void ParameterFitOptions::validate() const {
  if (parameters.empty())
    throw InputError("fit.parameters", "choose at least one parameter to fit");
  for (size_t i = 0; i < parameters.size(); ++i)
    for (size_t j = i + 1; j < parameters.size(); ++j)
      if (parameters[i] == parameters[j])
        throw InputError("fit.parameters", "'" + to_string(parameters[i]) + "' is listed twice");
  if (max_iterations < 1)
    throw InputError("fit.max_iterations", "must be >= 1, got " + std::to_string(max_iterations));
  if (frames == 0 || frames < -1)
    throw InputError("fit.frames", "must be >= 1 (or -1 for all), got " + std::to_string(frames));
  if (!(tolerance >= 0 && tolerance < 1))
    throw InputError("fit.tolerance", "must be in [0, 1), got " + std::to_string(tolerance));
  if (!(initial_lambda > 0 && std::isfinite(initial_lambda)))
    throw InputError(
        "fit.initial_lambda", "must be positive, got " + std::to_string(initial_lambda));
  if (max_rejections < 1)
    throw InputError("fit.max_rejections", "must be >= 1, got " + std::to_string(max_rejections));
  if (!(finite_difference_step > 0 && finite_difference_step < 1))
    throw InputError("fit.finite_difference_step",
        "must be in (0, 1), got " + std::to_string(finite_difference_step));
  if (!(max_step > 0 && std::isfinite(max_step)))
    throw InputError("fit.max_step", "must be positive, got " + std::to_string(max_step));
  if (!std::isfinite(error_tolerance))
    throw InputError(
        "fit.error_tolerance", "must be finite, got " + std::to_string(error_tolerance));
  if (!(young_scan_range >= 0 && young_scan_range <= 1e3))
    throw InputError("fit.young_scan_range",
        "must be in [0, 1000] (<= 1: no scan), got " + std::to_string(young_scan_range));
  if (!std::isfinite(alpha0_floor) || !std::isfinite(alpha1_floor))
    throw InputError("fit.alpha_floor", "damping floors must be finite");
}

ParameterFitReport fit_parameters(const sim::Scene& scene, material::ElasticModelType type,
    const NominalParameters& start, const observe::Observation& obs,
    const ParameterFitOptions& options, const ProgressCallback& progress) {
  const Motion motion { "observation", scene, obs };
  return fit_parameters(std::span<const Motion>(&motion, 1), type, start, options, progress);
}

ParameterFitReport fit_parameters(std::span<const Motion> data, material::ElasticModelType type,
    const NominalParameters& start, const ParameterFitOptions& options,
    const ProgressCallback& progress) {
  const auto t0 = Clock::now();
  options.validate();
  check_start(start, options.parameters);
  if (data.empty())
    throw InputError("fit", "no motion to fit");
  std::vector<FitMotion> motions;
  int samples = 0;
  double duration = 0;
  for (const Motion& m : data) {
    const observe::Observation& obs = m.observed;
    obs.validate(m.scene.mesh.num_vertices(), -1, m.scene.dt, m.name);
    if (obs.num_frames() < 2)
      throw InputError(m.name + ": /observed/positions", "needs at least 2 frames to fit a motion");
    const int frames = options.frames < 0 ? obs.num_frames() - 1 : options.frames;
    if (frames > obs.num_frames() - 1)
      throw InputError("fit.frames",
          std::to_string(frames) + " steps requested but " + m.name + " has only "
              + std::to_string(obs.num_frames() - 1) + " (frames 0.."
              + std::to_string(obs.num_frames() - 1) + ")");
    motions.push_back({ &m.scene, &obs, frames });
    // Seen (frame, vertex) entries of frames 0..frames: the RMS is over those.
    samples += static_cast<int>(std::max(1L, obs.frame_range(0, frames).num_valid()));
    duration = std::max(duration, frames * m.scene.dt);
  }
  const sim::Scene& scene = data.front().scene;
  const int frames = motions.front().frames;

  const ParameterTransform transform { options.alpha0_floor > 0 ? options.alpha0_floor
                                                                : 1e-2 / duration,
    options.alpha1_floor > 0 ? options.alpha1_floor : 1e-2 * scene.dt };
  const auto& fitted = options.parameters;
  const int p = static_cast<int>(fitted.size());
  const double error_floor = options.error_tolerance > 0
      ? options.error_tolerance
      : 1e-10 * scene.mesh.bounding_box_diagonal();
  int largest_dofs = 0;
  for (const Motion& m : data)
    largest_dofs = std::max(largest_dofs, 3 * m.scene.mesh.num_vertices());
  const bool parallel = options.parallel && largest_dofs <= kParallelFitMaxDofs;

  ParameterFitReport report;
  report.initial = report.fitted = start;
  report.frames = frames;

  auto record = [&](int iteration, const Evaluation& e, double lambda, int rejected) {
    ParameterFitIteration it;
    it.iteration = iteration;
    it.parameters = report.fitted;
    it.rms_error = e.rms(samples);
    it.max_error = e.max_error;
    it.lambda = lambda;
    it.rejected_steps = rejected;
    it.seconds = seconds_since(t0);
    report.history.push_back(it);
    if (progress)
      progress(iteration, options.max_iterations, describe(it));
  };
  auto finish = [&](const Evaluation& e, FitStop stop, std::string message) {
    report.final_rms = e.rms(samples);
    report.final_max = e.max_error;
    report.stop = stop;
    report.message = std::move(message);
    report.seconds = seconds_since(t0);
    return report;
  };

  const auto count_failure = [&](const Evaluation& e) {
    ++report.diverged;
    report.unheld_loads += e.load_not_held ? 1 : 0;
  };
  Evaluation current = evaluate(motions, type, start);
  ++report.simulations;
  if (!current.completed) {
    count_failure(current);
    report.seconds = seconds_since(t0);
    report.stop = interrupt_requested() ? FitStop::Interrupted : FitStop::StartDiverged;
    report.message = "the simulation with the start parameters failed: " + current.message;
    return report;
  }
  report.initial_rms = current.rms(samples);
  report.initial_max = current.max_error;
  record(0, current, options.initial_lambda, 0);
  if (std::find(fitted.begin(), fitted.end(), FitParameter::Young) != fitted.end()
      && options.young_scan_range > 1) {
    // The objective is multimodal in E: a model stiffer or softer by a factor (1 + 1/P)² drifts
    // a whole period out of phase over P observed periods, so Levenberg–Marquardt started a
    // factor 1.5–2 off can stop in the wrong phase. E = start × 2^(j/2) over the range puts a
    // sample within 2^(1/4) of every E, inside the right basin for P ≲ 4.
    std::vector<double> factors;
    const int half = static_cast<int>(std::floor(2 * std::log2(options.young_scan_range) + 1e-9));
    for (int j = -half; j <= half; ++j)
      if (j != 0)
        factors.push_back(std::exp2(0.5 * j));
    std::vector<Evaluation> scanned(factors.size());
    const auto scan = [&](size_t i) {
      NominalParameters trial = start;
      trial.young *= factors[i];
      scanned[i] = evaluate(motions, type, trial);
    };
    if (parallel) {
      tbb::parallel_for(size_t { 0 }, factors.size(), scan);
    } else {
      for (size_t i = 0; i < factors.size(); ++i)
        scan(i);
    }
    size_t best = factors.size();
    for (size_t i = 0; i < factors.size(); ++i) {
      ++report.simulations;
      if (!scanned[i].completed)
        count_failure(scanned[i]);
      else if (scanned[i].cost < (best < factors.size() ? scanned[best].cost : current.cost))
        best = i;
    }
    if (best < factors.size()) {
      report.fitted.young = start.young * factors[best];
      current = std::move(scanned[best]);
      record(0, current, options.initial_lambda, 0);
    }
  }

  // Levenberg–Marquardt in the transformed coordinates u. The current point is report.fitted,
  // `current` its evaluation; a trial waits in trial_parameters and `trial` until the driver
  // accepts or rejects it.
  FitStop stopped_by = FitStop::Interrupted; // why the problem ended the solve, when it did
  std::string stopped_because;
  const auto stop = [&](FitStop why, std::string message) {
    stopped_by = why;
    stopped_because = std::move(message);
  };
  const auto interrupted
      = [&] { stop(FitStop::Interrupted, "interrupted; the best parameters so far are kept"); };
  VecX u(p);
  NominalParameters trial_parameters;
  Evaluation trial;
  std::string last_failure; // the last trial's divergence ("" if it completed)
  const double h = options.finite_difference_step;

  LevenbergMarquardtProblem problem;
  problem.linearize = [&]() -> std::optional<NormalEquations> {
    if (current.rms(samples) <= error_floor) {
      stop(FitStop::Converged, "the observation is matched to round-off");
      return std::nullopt;
    }
    ++report.iterations;
    // Transformed coordinates of the current parameters (re-derived each time, so a damping
    // clamped at 0 sits at log(floor) where its forward difference is informative).
    for (int i = 0; i < p; ++i)
      u[i] = transform.to_u(fitted[i], report.fitted);

    // Forward-difference Jacobian: one simulation per parameter (backwards if forwards diverges).
    MatX J = MatX::Zero(current.residual.size(), p);
    std::vector<int> runs(static_cast<size_t>(p), 0), failures(static_cast<size_t>(p), 0),
        unheld(static_cast<size_t>(p), 0);
    const auto column = [&](int i) {
      for (const double step : { h, -h }) {
        NominalParameters perturbed = report.fitted;
        transform.set(fitted[i], u[i] + step, perturbed);
        const Evaluation e = evaluate(motions, type, perturbed);
        ++runs[static_cast<size_t>(i)];
        if (e.completed) {
          J.col(i) = (e.residual - current.residual) / step;
          return;
        }
        ++failures[static_cast<size_t>(i)];
        unheld[static_cast<size_t>(i)] += e.load_not_held ? 1 : 0;
        if (interrupt_requested())
          return;
      }
    };
    if (parallel) {
      tbb::parallel_for(0, p, column);
    } else {
      for (int i = 0; i < p; ++i)
        column(i);
    }
    for (int i = 0; i < p; ++i) {
      report.simulations += runs[static_cast<size_t>(i)];
      report.diverged += failures[static_cast<size_t>(i)];
      report.unheld_loads += unheld[static_cast<size_t>(i)];
    }
    if (interrupt_requested()) {
      interrupted();
      return std::nullopt;
    }
    // A column whose simulations all diverged (or that does not influence the motion) has a zero
    // diagonal in JᵀJ: the Marquardt scaling holds that parameter fixed.
    // A damping at 0 rests on its bound when the data ask for less (the fit of a nominal that
    // damps less than backward Euler already does, or of an undamped truth).
    VecX lower_step(p);
    for (int i = 0; i < p; ++i)
      lower_step[i] = std::min(0.0, transform.lower_u(fitted[i]) - u[i]);
    return NormalEquations { J.transpose() * J, J.transpose() * current.residual, current.cost,
      samples, std::move(lower_step) };
  };
  problem.evaluate = [&](const VecX& delta) {
    trial_parameters = report.fitted;
    for (int i = 0; i < p; ++i)
      transform.set(fitted[i], u[i] + delta[i], trial_parameters);
    trial = evaluate(motions, type, trial_parameters);
    ++report.simulations;
    if (interrupt_requested()) {
      interrupted();
      return TrialEvaluation { .stop = true };
    }
    if (!trial.completed)
      count_failure(trial);
    last_failure = trial.completed ? "" : trial.message;
    return TrialEvaluation { .completed = trial.completed, .cost = trial.cost };
  };
  problem.accept = [&] {
    current = std::move(trial);
    report.fitted = trial_parameters;
  };
  problem.on_step = [&](const LevenbergMarquardtStep& step) {
    if (step.accepted || step.gives_up)
      record(step.iteration, current, step.damping, step.rejections);
    return true;
  };

  const LevenbergMarquardtSummary summary = levenberg_marquardt(problem,
      { .max_iterations = options.max_iterations,
          .max_rejections = options.max_rejections,
          .initial_damping = options.initial_lambda,
          .scaling = DampingScaling::marquardt,
          .damping_decrease = 3,
          .min_damping = 1e-12,
          .damping_increase = 4,
          .failed_damping_increase = 10, // a diverged trial was a long step: shrink harder
          .max_step = options.max_step,
          .function_tolerance = options.tolerance });
  switch (summary.stop) {
  case LevenbergMarquardtStop::stopped:
    return finish(current, stopped_by, stopped_because);
  case LevenbergMarquardtStop::converged: {
    char buf[96];
    std::snprintf(buf, sizeof buf, "relative improvement %.2g below the tolerance %.2g",
        summary.relative_decrease, options.tolerance);
    return finish(current, FitStop::Converged, buf);
  }
  case LevenbergMarquardtStop::no_improving_step:
    return finish(current, FitStop::NoImprovingStep,
        std::to_string(summary.rejections) + " trial steps in a row did not lower the error"
            + (last_failure.empty() ? std::string() : " (last: " + last_failure + ")"));
  case LevenbergMarquardtStop::degenerate:
    return finish(current, FitStop::NoImprovingStep,
        "no fitted parameter changes the observed motion (or every perturbed simulation "
        "diverged)");
  case LevenbergMarquardtStop::max_iterations:
  case LevenbergMarquardtStop::max_steps:
    break;
  }
  return finish(current, FitStop::MaxIterations,
      "reached " + std::to_string(options.max_iterations) + " iterations");
}

} // namespace elastolearn::learn
