#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/forward_fit.hpp>
#include <elastolearn/learn/levenberg_marquardt.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/stability_cuts.hpp>
#include <elastolearn/learn/trajectory_physics.hpp>
#include <elastolearn/sim/forward_run.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <elastolearn/core/timing.hpp>
#include <elastolearn/sim/linear_solver.hpp>
#include <elastolearn/sim/run_ahead.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

namespace elastolearn::learn {

namespace {

/// The observed entries among the free dofs: (free dof, observation vertex slot, component).
struct ObservedDof {
  int free = 0;
  int slot = 0;
  int component = 0;
};

std::vector<ObservedDof> observed_free_dofs(
    const fem::DofMap& dofs, const observe::Observation& observed) {
  std::vector<ObservedDof> out;
  for (int j = 0; j < observed.num_observed(); ++j)
    for (int c = 0; c < 3; ++c) {
      const int free = dofs.free_index(3 * observed.vertex_ids[j] + c);
      if (free >= 0)
        out.push_back({ free, j, c });
    }
  return out;
}

} // namespace

void ForwardFitOptions::validate() const {
  if (max_iterations < 0)
    throw InputError(
        "forward_fit.max_iterations", "must be ≥ 0, got " + std::to_string(max_iterations));
  if (!std::isfinite(damping) || damping <= 0)
    throw InputError("forward_fit.damping", "must be finite and > 0");
  if (!std::isfinite(function_tolerance) || function_tolerance < 0)
    throw InputError("forward_fit.function_tolerance", "must be finite and ≥ 0");
  if (!std::isfinite(noise) || noise < 0)
    throw InputError("forward_fit.noise", "must be finite and ≥ 0");
  if (!std::isfinite(damping_prior) || damping_prior < 0)
    throw InputError("forward_fit.damping_prior", "must be finite and ≥ 0");
  if (!std::isfinite(elastic_prior) || elastic_prior < 0)
    throw InputError("forward_fit.elastic_prior", "must be finite and ≥ 0");
  if (sensitivities == Sensitivities::none)
    throw InputError(
        "forward_fit.sensitivities", "the fit needs sensitivities (projected or exact)");
}

namespace {

/// simulate_with_sensitivities of one motion, but for its `seconds`.
ForwardSensitivityPass untimed_pass(const sim::Scene& scene, const observe::Observation& observed,
    const ReconstructionMesh& mesh, const RbfDesign& design, const VecX& unknowns,
    Sensitivities mode, const ProgressCallback& progress) {
  const bool sensitivities = mode != Sensitivities::none;
  ForwardSensitivityPass pass;
  const sim::Scene corrected = sim::with_correction(
      scene, std::make_shared<material::RbfCorrection>(design.correction(unknowns)));
  sim::Simulator simulator(corrected);
  const auto initial = simulator.apply_initial_condition();
  if (!initial.converged) {
    pass.message = "initial condition: " + initial.message;
    return pass;
  }
  TrajectoryPhysics physics(corrected);
  physics.set_project_tangent(mode != Sensitivities::exact);
  const fem::DofMap& dofs = physics.dofs();
  const int u = design.num_unknowns(), n_free = dofs.num_free();
  const double h = scene.dt;
  VecX masses;
  dofs.restrict_into(physics.dof_masses(), masses);
  const std::vector<ObservedDof> observed_dofs = observed_free_dofs(dofs, observed);
  const int k = static_cast<int>(observed_dofs.size());

  // Work space, allocated once: the system matrices share the pattern, CHOLMOD analyses it once.
  fem::SystemMatrix system = physics.make_matrix(), damping = physics.make_matrix();
  const std::unique_ptr<sim::LinearSolver> solver
      = sim::make_linear_solver(sim::LinearSolverType::Cholmod);
  std::unique_ptr<CorrectionForceJacobian> jacobian;
  MatX s_now, s_previous, s_before, rhs, observed_rows(k, u);
  VecX residual, observed_error(k);
  if (sensitivities) {
    solver->analyze(system.matrix());
    jacobian = std::make_unique<CorrectionForceJacobian>(mesh, dofs, design);
    s_previous = MatX::Zero(n_free, u);
    pass.normal = MatX::Zero(u, u);
    pass.gradient = VecX::Zero(u);
  }

  std::vector<VecX> frames;
  frames.reserve(static_cast<size_t>(scene.frames) + 1);
  frames.push_back(simulator.positions());
  const VecX x_start_before = simulator.positions() - h * simulator.velocities(); // x_{−1}
  if (sensitivities && corrected.initial.kind == sim::InitialCondition::Kind::StaticLoad) {
    // Static start f(x_0, 0; w) + loads = 0: K_0 S_0 = ∂f_0/∂w, and x_{−1} = x_0 moves with it.
    physics.residual(frames[0], frames[0], frames[0], 0.0, residual);
    physics.jacobians(system, damping); // K + D/h and D at v = 0
    const fem::SparseMatrix k0 = system.matrix() - damping.matrix() / h;
    rhs = jacobian->transposed(frames[0], VecX::Zero(frames[0].size()), physics.elastic_force())
              .transpose();
    if (!solver->factorize(k0) || !solver->solve(rhs, s_previous, 0.0)) {
      pass.message = "the initial stiffness is not positive definite";
      return pass;
    }
  }
  if (sensitivities)
    s_before = s_previous;

  const auto accumulate = [&](int t, const VecX& x) { // the Gauss–Newton sums of frame t
    for (int i = 0; i < k; ++i) {
      const ObservedDof& o = observed_dofs[i];
      if (!observed.is_valid(t, o.slot)) { // a lost entry adds nothing to E
        observed_error[i] = 0;
        observed_rows.row(i).setZero();
        continue;
      }
      observed_error[i] = x[dofs.free_dofs()[o.free]] - observed.positions[t](o.slot, o.component);
      observed_rows.row(i) = s_now.row(o.free);
    }
    pass.normal.selfadjointView<Eigen::Lower>().rankUpdate(observed_rows.transpose());
    pass.gradient.noalias() += observed_rows.transpose() * observed_error;
  };
  if (sensitivities) {
    s_now = s_previous;
    accumulate(0, frames[0]);
  }

  // The simulation runs ahead on its own thread: frame t's sensitivities need frames t − 2 … t
  // only, and overlap the steps after t.
  sim::RunAhead ahead(simulator, scene.frames);
  for (int t = 1; t <= scene.frames; ++t) {
    if (!ahead.wait_for(t)) {
      pass.message = ahead.message();
      return pass;
    }
    frames.push_back(ahead.positions(t));
    if (sensitivities) {
      const VecX& x_before = t >= 2 ? frames[t - 2] : x_start_before;
      physics.residual(x_before, frames[t - 1], frames[t], ahead.time(t), residual);
      physics.jacobians(system, damping); // K + D/h and D at the converged step
      system.add_diagonal(masses, 1.0 / (h * h));
      const bool factored = solver->factorize(system.matrix());
      if (!factored) {
        pass.message
            = "frame " + std::to_string(t) + ": the step's Jacobian is not positive definite";
        return pass;
      }
      const VecX velocity = (frames[t] - frames[t - 1]) / h;
      // The residual's force pass left the elements' SVDs at x_t: J reuses them.
      rhs = jacobian->transposed(frames[t], velocity, physics.elastic_force()).transpose();
      rhs.noalias() += (2.0 / (h * h)) * masses.asDiagonal() * s_previous;
      rhs.noalias() += (damping.matrix() * s_previous) / h;
      rhs.noalias() -= (1.0 / (h * h)) * masses.asDiagonal() * s_before;
      if (!solver->solve(rhs, s_now, 0.0)) {
        pass.message = "frame " + std::to_string(t) + ": the sensitivity solve failed";
        return pass;
      }
      std::swap(s_before, s_previous);
      s_previous = s_now;
      accumulate(t, frames[t]);
    }
    if (progress)
      progress(t, scene.frames,
          sensitivities ? "forward simulation with sensitivities" : "forward simulation");
  }
  pass.completed = true;
  pass.error = observation_error(frames, observed);
  pass.squared_error = pass.error.rms * pass.error.rms * double(pass.error.samples);
  if (sensitivities)
    pass.normal.triangularView<Eigen::StrictlyUpper>() = pass.normal.transpose();
  return pass;
}

} // namespace

ForwardSensitivityPass simulate_with_sensitivities(const sim::Scene& scene,
    const observe::Observation& observed, const ReconstructionMesh& mesh, const RbfDesign& design,
    const VecX& unknowns, Sensitivities mode, const ProgressCallback& progress) {
  const auto start = Clock::now(); // a failed pass reports its time too
  ForwardSensitivityPass pass
      = untimed_pass(scene, observed, mesh, design, unknowns, mode, progress);
  pass.seconds = seconds_since(start);
  return pass;
}

ForwardSensitivityPass simulate_with_sensitivities(std::span<const Motion> motions,
    std::span<const ReconstructionMesh> meshes, const RbfDesign& design, const VecX& unknowns,
    Sensitivities mode, const ProgressCallback& progress) {
  if (motions.empty() || motions.size() != meshes.size())
    throw InputError("forward_fit.motions",
        "needs one reconstruction mesh per motion and at least one motion (got "
            + std::to_string(motions.size()) + " motions, " + std::to_string(meshes.size())
            + " meshes)");
  ForwardSensitivityPass total;
  std::vector<ErrorSummary> errors;
  errors.reserve(motions.size());
  for (size_t i = 0; i < motions.size(); ++i) {
    ForwardSensitivityPass pass = simulate_with_sensitivities(
        motions[i].scene, motions[i].observed, meshes[i], design, unknowns, mode, progress);
    if (!pass.completed) {
      if (motions.size() > 1)
        pass.message = "motion " + motions[i].name + ": " + pass.message;
      pass.seconds += total.seconds;
      return pass;
    }
    errors.push_back(pass.error);
    if (i == 0) {
      total = std::move(pass);
      continue;
    }
    total.squared_error += pass.squared_error;
    if (mode != Sensitivities::none) {
      total.normal += pass.normal;
      total.gradient += pass.gradient;
    }
    total.seconds += pass.seconds;
  }
  total.error = combined_error(errors);
  return total;
}

ForwardFitResult fit_to_observations(const sim::Scene& scene, const observe::Observation& observed,
    const ReconstructionMesh& mesh, const RbfDesign& design, const VecX& start,
    const ForwardFitOptions& options, const ProgressCallback& progress,
    const ForwardFitStepCallback& on_step) {
  const Motion motion { scene.name, scene, observed };
  return fit_to_observations(
      std::span(&motion, 1), std::span(&mesh, 1), design, start, options, progress, on_step);
}

ForwardFitResult fit_to_observations(std::span<const Motion> motions,
    std::span<const ReconstructionMesh> meshes, const RbfDesign& design, const VecX& start,
    const ForwardFitOptions& options, const ProgressCallback& progress,
    const ForwardFitStepCallback& on_step) {
  options.validate();
  const auto started = Clock::now();
  ForwardFitResult result;
  result.unknowns = start;
  ForwardSensitivityPass current = simulate_with_sensitivities(
      motions, meshes, design, start, options.sensitivities, progress);
  if (!current.completed)
    throw InputError(
        "forward_fit", "the starting correction's simulation diverged (" + current.message + ")");
  result.rms_history.push_back(current.error.rms);
  const int first_damping = design.elastic_unknowns(), n_damping = design.damping_unknowns();
  // The priors ρ Σ (s_i w_i)² on the damping (ρ_d) and the elastic (ρ_e) unknowns and the
  // smoothness penalty wᵀ R w (RbfDesign::smoothness_penalty), with s and R fixed by the current
  // pass so that the trial and the current objective are measured alike (and a resumed fit,
  // which recomputes the current pass, takes the same steps).
  VecX prior_weights;
  MatX smoothness;
  const auto objective = [&](const ForwardSensitivityPass& pass, const VecX& w) {
    return pass.squared_error + w.dot(prior_weights.cwiseProduct(w)) + w.dot(smoothness * w);
  };
  // The current point is result.unknowns with its pass `current`; a trial waits in trial_unknowns
  // and `trial`.
  VecX trial_unknowns;
  ForwardSensitivityPass trial;
  // A trial's Δα₀ is kept ≥ −α₀ of the nominal (at rest): below, the simulation clamps the mass
  // damping at 0 and Δα₀'s column −M v no longer describes what a step changes. The bound is a
  // condition of the step's solve (NormalEquations::lower_step: held there, the other unknowns
  // are solved again), not only a clamp of the solved step, whose other unknowns would have moved
  // for a Δα₀ the trial does not get.
  const int mass = design.mass_damping_unknown();
  const auto& damping = motions.front().scene.material.damping;
  const double mass_floor = damping ? -damping->coefficients(1.0).alpha0 : 0.0;
  const auto mass_floor_step = [&] {
    VecX lower;
    if (mass >= 0) {
      lower = VecX::Constant(start.size(), -std::numeric_limits<double>::infinity());
      lower[mass] = mass_floor - result.unknowns[mass];
    }
    return lower;
  };
  LevenbergMarquardtProblem problem;
  problem.linearize = [&]() -> std::optional<NormalEquations> {
    prior_weights = VecX::Zero(start.size());
    prior_weights.head(first_damping)
        = options.elastic_prior * current.normal.diagonal().head(first_damping);
    prior_weights.segment(first_damping, n_damping)
        = options.damping_prior * current.normal.diagonal().segment(first_damping, n_damping);
    smoothness = design.smoothness_penalty(current.normal);
    NormalEquations equations { current.normal,
      current.gradient + prior_weights.cwiseProduct(result.unknowns) + smoothness * result.unknowns,
      objective(current, result.unknowns), current.error.samples, mass_floor_step() };
    equations.hessian.diagonal() += prior_weights;
    equations.hessian += smoothness;
    return equations;
  };
  const auto stability_of = [&](const VecX& unknowns) {
    const material::RbfCorrection c = design.correction(unknowns);
    return material_stability(
        *motions.front().scene.material.elastic, &c, options.stability_stretches);
  };
  const auto trial_at = [&](double fraction, const VecX& step) {
    trial_unknowns = result.unknowns + fraction * step;
    if (mass >= 0)
      trial_unknowns[mass] = std::max(trial_unknowns[mass], mass_floor);
  };
  // The longest fraction 2⁻ᵏ (k ≤ kStabilityStepHalvings) of `step` whose material is stable
  // into trial_unknowns, and its stability (unstable if no fraction is). A step to an unstable
  // material is shortened along its direction first: the check costs no simulation, so a trial
  // is spent on a simulated step whenever a shorter one is stable (rejecting it instead would
  // cost a whole trial and only grow μ).
  const auto shorten = [&](const VecX& step) {
    trial_at(1.0, step);
    StabilityReport stability = stability_of(trial_unknowns);
    for (int halving = 1; !stability.stable() && halving <= kStabilityStepHalvings; ++halving) {
      trial_at(std::ldexp(1.0, -halving), step);
      stability = stability_of(trial_unknowns);
    }
    return stability;
  };
  // Where no fraction of the step is stable, the step solved subject to stability cuts instead
  // (stability_cuts.hpp), which would otherwise be rejected unsimulated. Only there: a cut step
  // turns along the stability boundary, and cutting every step that shortening serves measured
  // worse on most named cases (docs/learning_recipe.md, "Stability cuts").
  if (options.stability_cuts && options.stability_stretches.rows() > 0)
    problem.solve_step = [&](const RegularisedNormalEquations& equations, const VecX& rhs,
                             const LinearInequalities& bounds) {
      VecX step = solve_with_inequalities(equations, rhs, bounds);
      if (!shorten(step).stable())
        step = stable_least_squares(equations, rhs, design, *motions.front().scene.material.elastic,
            options.stability_stretches, result.unknowns, 8, bounds)
                   .x;
      return step;
    };
  problem.evaluate = [&](const VecX& step) {
    trial_at(1.0, step);
    if (options.stability_stretches.rows() > 0) {
      const StabilityReport stability = shorten(step);
      if (!stability.stable()) {
        trial = {};
        trial.unstable = true;
        trial.message = "not simulated: the trial's material is "
            + describe_unstable(stability, "stretch samples");
        result.rms_history.push_back(-1.0);
        return TrialEvaluation { .completed = false };
      }
    }
    trial = simulate_with_sensitivities(
        motions, meshes, design, trial_unknowns, options.sensitivities, progress);
    result.rms_history.push_back(trial.completed ? trial.error.rms : -1.0);
    TrialEvaluation evaluation { .completed = trial.completed };
    if (trial.completed)
      evaluation.cost = objective(trial, trial_unknowns);
    return evaluation;
  };
  problem.accept = [&] {
    result.unknowns = trial_unknowns;
    current = std::move(trial);
  };
  if (on_step)
    problem.on_step = [&](const LevenbergMarquardtStep& step) {
      return on_step(step.accepted ? current : trial, step.accepted, result.unknowns, step.damping);
    };
  // Levenberg–Marquardt on the Jacobi-scaled normal equations, (Ĥ + μ I) Δ̂ = −ĝ: the RBF fit's
  // regularised solve with μ as its (dimensionless) Tikhonov weight. Every trial counts against
  // max_iterations; the equations change only with an accepted step's pass.
  const int unlimited = std::numeric_limits<int>::max();
  const LevenbergMarquardtSummary summary = levenberg_marquardt(problem,
      { .max_iterations = unlimited,
          .max_steps = options.max_iterations,
          .max_rejections = unlimited,
          .initial_damping = options.damping,
          .scaling = DampingScaling::jacobi,
          .damping_decrease = 3,
          .min_damping = 0,
          .damping_increase = 10,
          .failed_damping_increase = 10,
          .function_tolerance = options.function_tolerance,
          .cost_floor = 3 * options.noise * options.noise * double(current.error.samples) });
  result.accepted = summary.accepted;
  result.converged = summary.stop == LevenbergMarquardtStop::converged;
  result.seconds = seconds_since(started);
  return result;
}

} // namespace elastolearn::learn
