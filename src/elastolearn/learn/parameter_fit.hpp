#pragma once
/// \file The parameter-fitting baseline (paper 000's reference [14]; docs/learning.md
/// "Parameter-fitting baseline"): fit Young's modulus, Poisson's ratio and the Rayleigh
/// coefficients α₀, α₁ of the nominal model so that forward simulation matches observed vertex
/// positions, by Levenberg–Marquardt on forward simulations. The learned correction must beat it
/// where the nominal model is wrong in kind (paper Fig. 11).
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/motion.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace elastolearn::learn {

/// The scalar parameters of the nominal model (constant Rayleigh damping).
struct NominalParameters {
  double young = 0; ///< E [Pa], > 0
  double poisson = 0; ///< ν, in (−1, 0.5)
  double alpha0 = 0; ///< mass-proportional damping [1/s], ≥ 0
  double alpha1 = 0; ///< stiffness-proportional damping [s], ≥ 0
};

/// A fittable parameter. Names (JSON and CLI): "young", "poisson", "alpha0", "alpha1".
enum class FitParameter { Young, Poisson, Alpha0, Alpha1 };

std::string to_string(FitParameter parameter);
/// Inverse of to_string; throws InputError(where, ...) listing the valid names.
FitParameter fit_parameter_from_string(
    std::string_view name, const std::string& where = "parameter");
/// A comma-separated list ("young,alpha1"); throws InputError(where, ...) on an unknown or
/// repeated name or an empty list.
std::vector<FitParameter> fit_parameters_from_string(
    std::string_view list, const std::string& where = "--fit");

/// The scene with the nominal material replaced: the elastic model of `type` with Lamé
/// parameters from (E, ν) and constant Rayleigh damping (α₀, α₁); density and any correction are
/// kept. For SplineEdited, the scene's model must be a SplineEditedModel; its base, region and
/// spline are kept. Throws InputError for invalid values or a SplineEdited type the scene lacks.
sim::Scene scene_with_parameters(
    const sim::Scene& scene, material::ElasticModelType type, const NominalParameters& parameters);

/// Largest system (3 × vertices) whose finite-difference simulations run concurrently.
inline constexpr int kParallelFitMaxDofs = 20000;

struct ParameterFitOptions {
  /// Which parameters move (the others stay at their start values). Non-empty, no repeats.
  std::vector<FitParameter> parameters
      = { FitParameter::Young, FitParameter::Poisson, FitParameter::Alpha0, FitParameter::Alpha1 };
  int max_iterations = 20; ///< Levenberg–Marquardt iterations (Jacobian evaluations), ≥ 1
  /// Simulated steps compared with the observation (frames 0..frames); −1 = all (T − 1).
  /// Fewer frames make every simulation proportionally faster.
  int frames = -1;
  /// Stop when an accepted step lowers the objective by less than this fraction.
  double tolerance = 1e-4;
  /// Stop when the RMS observation error falls to this [m]; ≤ 0 picks 10⁻¹⁰ × the rest
  /// bounding-box diagonal (round-off: only reached by data from the same simulator).
  double error_tolerance = 0;
  double initial_lambda = 1e-3; ///< Levenberg–Marquardt damping λ (relative to diag JᵀJ)
  int max_rejections = 8; ///< rejected trial steps in a row before giving up
  /// Forward-difference step in the transformed parameters (log E, logit ν, log(α + floor)).
  double finite_difference_step = 1e-3;
  /// Largest step per transformed parameter in one iteration (e.g. 1.5: E changes by ≤ e^1.5).
  double max_step = 1.5;
  /// Floors of the damping transforms log(α + floor) [1/s] and [s]; ≤ 0 picks 10⁻² / duration
  /// for α₀ and 10⁻² · dt for α₁ (far below any damping visible over the observed motion).
  double alpha0_floor = 0;
  double alpha1_floor = 0;
  /// Before Levenberg–Marquardt, when E is fitted: simulate E = start × 2^(j/2) over
  /// [start / range, start × range] and start from the best (the objective is multimodal in E:
  /// a model out of phase by a whole period is a local minimum). ≤ 1: no scan. The default
  /// range 4 costs 8 simulations.
  double young_scan_range = 4;
  /// Run the finite-difference simulations of one Jacobian concurrently (oneTBB); each holds
  /// its own simulator (mesh, matrix, factorisation), so memory grows with the parameter count.
  /// Meshes of more than kParallelFitMaxDofs unknowns run them one after the other: each
  /// simulation's factorisation then already uses every core (threaded BLAS).
  bool parallel = true;
  /// Throws InputError naming the offending option.
  void validate() const;
};

/// Why the fit stopped.
enum class FitStop {
  Converged, ///< relative improvement below tolerance (or the error is zero)
  MaxIterations, ///< iteration budget used
  NoImprovingStep, ///< max_rejections trial steps in a row did not lower the objective
  StartDiverged, ///< the simulation with the start parameters failed; nothing was fitted
  Interrupted, ///< interrupt requested (Ctrl-C); the best parameters so far are returned
};
std::string to_string(FitStop stop);

/// One accepted (or final) state of the fit.
struct ParameterFitIteration {
  int iteration = 0; ///< 0 = start
  NominalParameters parameters;
  double rms_error = 0; ///< √(mean over (frame, observed vertex) of ‖x_sim − x_obs‖²) [m]
  double max_error = 0; ///< max over (frame, observed vertex) of ‖x_sim − x_obs‖ [m]
  double lambda = 0; ///< LM damping after this iteration
  int rejected_steps = 0; ///< trial steps rejected in this iteration (diverged or worse)
  double seconds = 0; ///< wall time since the fit started
};

struct ParameterFitReport {
  NominalParameters initial;
  NominalParameters fitted; ///< best parameters found (= initial if nothing improved)
  double initial_rms = 0, initial_max = 0; ///< observation errors of the start [m]
  double final_rms = 0, final_max = 0; ///< observation errors of `fitted` [m]
  int iterations = 0; ///< Jacobian evaluations
  int simulations = 0; ///< forward simulations run (including finite differences)
  int diverged = 0; ///< of those, simulations that failed (rejected or retried)
  /// Of the failed simulations, those whose initial static solve failed: parameters under which
  /// no equilibrium was found for a motion's initial load (InitialCondition::StaticLoad), as
  /// with E-scan probes far softer than the object, which the load collapses (elements invert).
  /// The object held that load in its first observed frame: the data rule such parameters out;
  /// no motion was simulated with them.
  int unheld_loads = 0;
  int frames = 0; ///< simulated steps per simulation
  double seconds = 0; ///< total wall time
  FitStop stop = FitStop::MaxIterations;
  std::string message; ///< human-readable reason (names a divergence's frame)
  std::vector<ParameterFitIteration> history; ///< start, then every accepted iteration
  /// Point-cloud captures only (learn_material): the parameters of the nominal their clouds were
  /// last tracked with (the first fit's; the fit above is then the refit from that tracking).
  std::optional<NominalParameters> tracked_with;
};

/// Fit the nominal parameters to the observation by minimising
///   Φ(p) = Σ_t Σ_j ‖x_{v_j}(t; p) − s_j(t)‖²   (t = 0..frames, v_j = obs.vertex_ids[j],
///                                              over the entries seen: Observation::valid)
/// over x(p), the forward simulation of `scene` with the material of
/// scene_with_parameters(scene, type, p). Observation frame t is simulated frame t.
/// Levenberg–Marquardt on transformed parameters u = (log E, logit(ν/0.49), log(α₀ + floor₀),
/// log(α₁ + floor₁)), so every trial is valid (E > 0, 0 < ν < 0.49, α ≥ 0); Jacobian by forward
/// differences (one simulation per fitted parameter; a diverging one retries backwards). A trial
/// whose simulation diverges is a rejected step (λ grows), never an exception.
/// `progress(iteration, max_iterations, line)` is called at the start and after every iteration
/// with a one-line summary (error, parameters, time).
/// Throws InputError if the options are invalid, the observation does not fit the scene (ids,
/// dt, too few frames) or a fitted ν starts outside (0, 0.49) or a start value is invalid.
ParameterFitReport fit_parameters(const sim::Scene& scene, material::ElasticModelType type,
    const NominalParameters& start, const observe::Observation& obs,
    const ParameterFitOptions& options = {}, const ProgressCallback& progress = {});

/// The same fit to several motions of one object at once: Φ is summed over them (each scene's
/// material is replaced as above; `frames` applies to each motion). Errors name the motion.
ParameterFitReport fit_parameters(std::span<const Motion> motions, material::ElasticModelType type,
    const NominalParameters& start, const ParameterFitOptions& options = {},
    const ProgressCallback& progress = {});

} // namespace elastolearn::learn
