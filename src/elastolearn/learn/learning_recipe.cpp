#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/stacked_rows.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/cloud_motion.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/spline_edited.hpp>
#include <elastolearn/material/stvk.hpp>
#include <elastolearn/observe/observation_noise.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace elastolearn::learn {

RecipeOptions::RecipeOptions() {
  // As fit-parameters: with 10, 12 of random seed 9's 30 fits stopped at the cap, one of them
  // (a truth in the nominal's family, exact data) at 0.28 % where 20 reach the truth exactly.
  parameter_fit.max_iterations = 20;
  loop.forward_fit.max_iterations = 8;
  loop.forward_fit.function_tolerance = 0.01;
  loop.backtrack = true;
  loop.rbf.energy_kernels = true;
  loop.rbf.epsilon = 0.03;
  loop.rbf.smoothness = 1e-2;
  // The neo-Hookean tail and Δα₀ together (docs/learning_recipe.md, "The nominal's damping,
  // learned with the correction"): the parameter fit's α₀ absorbs part of the corotated
  // nominal's elastic misfit, and a correction learned with α₀ held there compensates for it;
  // learn_material applies both only where the fitted α₀ is positive.
  loop.rbf.neo_hookean_tail = true;
  loop.rbf.mass_damping = true;
  // Fits held stable by cuts rather than only shrunk or rejected (docs/learning_recipe.md,
  // "Stability cuts").
  loop.stability_cuts = true;
  loop.forward_fit.stability_cuts = true;
}

void RecipeOptions::validate() const {
  if (!std::isfinite(noise))
    throw InputError("learn.noise", "must be finite (< 0: estimate it)");
  if (!(validation_fraction > 0 && validation_fraction < 0.5))
    throw InputError("learn.validation_fraction", "must be in (0, 0.5)");
  parameter_fit.validate();
  loop.validate();
  network.validate();
}

fem::MaterialModel RecipeResult::material(
    const fem::MaterialModel& given_nominal, int candidate) const {
  const Candidate& c = candidate < 0 ? choice() : candidates.at(static_cast<size_t>(candidate));
  fem::MaterialModel m = c.kind == CandidateKind::Nominal ? given_nominal : fitted_nominal;
  m.correction = c.correction;
  return m;
}

NominalParameters nominal_parameters_of(
    const fem::MaterialModel& material, material::ElasticModelType& type) {
  using namespace material;
  const ElasticModel* elastic = material.elastic.get();
  const Lame* lame = nullptr;
  if (const auto* m = dynamic_cast<const CorotatedModel*>(elastic)) {
    type = ElasticModelType::Corotated;
    lame = &m->lame();
  } else if (const auto* s = dynamic_cast<const StVKModel*>(elastic)) {
    type = ElasticModelType::StVK;
    lame = &s->lame();
  } else if (const auto* n = dynamic_cast<const NeoHookeanModel*>(elastic)) {
    type = ElasticModelType::NeoHookean;
    lame = &n->lame();
  } else if (const auto* e = dynamic_cast<const SplineEditedModel*>(elastic)) {
    type = ElasticModelType::SplineEdited;
    lame = &e->lame();
  } else {
    throw InputError("material",
        "the nominal elastic model has no Young's modulus and Poisson "
        "ratio to fit");
  }
  NominalParameters p;
  p.young = lame->mu * (3 * lame->lambda + 2 * lame->mu) / (lame->lambda + lame->mu);
  p.poisson = lame->lambda / (2 * (lame->lambda + lame->mu));
  if (material.damping) {
    const auto* rayleigh = dynamic_cast<const RayleighDamping*>(material.damping.get());
    if (!rayleigh)
      throw InputError("material.damping",
          "learning fits constant Rayleigh coefficients first; the nominal damping is "
          "stretch-dependent");
    const RayleighCoefficients c = rayleigh->coefficients(1.0);
    p.alpha0 = c.alpha0;
    p.alpha1 = c.alpha1;
  }
  return p;
}

namespace {

/// How many of the loop's corrections are validated (those with the lowest training errors).
constexpr size_t kLoopCandidates = 3;
/// The forward fit's plateau: its accepted steps whose training RMS is within this fraction of
/// its last one's are all validated.
constexpr double kPlateau = 0.01;

/// Frames [first, last] of an observation (first becomes frame 0).
observe::Observation frame_range(const observe::Observation& o, int first, int last) {
  return o.frame_range(first, last);
}

/// A held-out piece of one motion: its scene, simulated in full, and the frames of it compared.
struct HeldOut {
  Motion motion; ///< observed = the frames compared (as recorded)
  int first_frame = 0; ///< frame of the scene's run that observed[0] is
};

/// The training and validation data of stage 1.
struct Split {
  /// Observations as recorded (what the parameter fit, the forward error and the forward fit
  /// compare with), and smoothed to the noise level (what the space-time stages follow).
  std::vector<Motion> training;
  std::vector<HeldOut> validation; ///< one per motion
  std::string description;
};

/// Every motion's last `validation_fraction` of frames is held out, the rest is trained on: the
/// loop learns from every kind of motion given, and the validation sees every kind. (Holding out
/// a whole motion instead would leave a training set of two motions one to learn from: a bend
/// and a twist of a bar then fit ν to the bend alone.) The training pieces' `smoothed` is left
/// null: prepare_data smooths their frames alone.
Split split_motions(std::span<const Motion> motions, double validation_fraction) {
  Split split;
  std::string pieces;
  for (size_t i = 0; i < motions.size(); ++i) {
    const Motion& m = motions[i];
    const int frames = m.scene.frames;
    const int held_out = std::max(1, static_cast<int>(std::lround(validation_fraction * frames)));
    const int train_frames = frames - held_out;
    if (train_frames < 4)
      throw InputError(m.name,
          "too few frames (" + std::to_string(frames) + ") to hold out the last "
              + std::to_string(held_out) + " for validation");
    Motion train = m;
    train.scene.frames = train_frames;
    train.observed = frame_range(m.observed, 0, train_frames);
    train.smoothed = nullptr;
    split.training.push_back(std::move(train));
    HeldOut piece { m, train_frames + 1 };
    piece.motion.observed = frame_range(m.observed, train_frames + 1, frames);
    split.validation.push_back(std::move(piece));
    if (i > 0)
      pieces += ", ";
    pieces += std::to_string(held_out) + " of " + std::to_string(frames) + " frames of " + m.name;
  }
  split.description = "the last " + to_text(100 * validation_fraction) + " %: " + pieces;
  return split;
}

/// The positions of the observed vertices in `frames` (those of `o`), flat (frame, observed
/// vertex, xyz); 0 at o's lost entries, so that they take no part in a comparison.
VecX at_observed_vertices(std::span<const VecX> frames, const observe::Observation& o) {
  const Eigen::Index k = o.num_observed();
  VecX out = VecX::Zero(static_cast<Eigen::Index>(frames.size()) * k * 3);
  for (size_t t = 0; t < frames.size(); ++t)
    for (Eigen::Index j = 0; j < k; ++j)
      if (o.is_valid(static_cast<int>(t), static_cast<int>(j)))
        out.segment<3>((static_cast<Eigen::Index>(t) * k + j) * 3)
            = frames[t].segment<3>(3 * o.vertex_ids[static_cast<size_t>(j)]);
  return out;
}

/// An observation's positions, flat like at_observed_vertices (0 at lost entries).
VecX flat_positions(const observe::Observation& o) {
  const Eigen::Index k = o.num_observed();
  VecX out = VecX::Zero(static_cast<Eigen::Index>(o.num_frames()) * k * 3);
  for (int t = 0; t < o.num_frames(); ++t)
    for (Eigen::Index j = 0; j < k; ++j)
      if (o.is_valid(t, static_cast<int>(j)))
        out.segment<3>((static_cast<Eigen::Index>(t) * k + j) * 3)
            = o.positions[static_cast<size_t>(t)].row(j).transpose();
  return out;
}

/// A candidate's predictions (at_observed_vertices, the motions in order; empty if a simulation
/// diverged).
struct CandidatePredictions {
  VecX held_out; ///< of the held-out observations
  VecX training; ///< of the training observations (as recorded)
};

/// Where the reference material (the fitted nominal, or the given one without a fit) goes in
/// every whole motion, training and held-out frames; simulating the held-out frames uses none of
/// their observations.
struct ReferenceReach {
  /// Where every correction must be stable, in the validation (Candidate::stability) and in the
  /// forward fit before it: learn::reachable_stretches around the runs. Empty if a run diverged
  /// (the reference then is no candidate either).
  MatX stretches;
  std::vector<std::vector<VecX>> runs; ///< per held-out motion, the reference's positions
};

ReferenceReach reference_reach(const Split& split, const fem::MaterialModel& reference,
    const StretchSampleOptions& sampling, const ProgressCallback& progress) {
  ReferenceReach reach;
  std::vector<MatX> run_stretches;
  for (const HeldOut& piece : split.validation) {
    sim::Scene scene = piece.motion.scene;
    scene.material = reference;
    sim::ForwardRun run = sim::simulate_positions(scene, progress);
    if (!run.completed)
      return {};
    run_stretches.push_back(
        collect_stretches(ReconstructionMesh(scene.mesh, reference), run.positions, sampling));
    reach.runs.push_back(std::move(run.positions));
  }
  reach.stretches = reachable_stretches(*reference.elastic, stacked_rows(run_stretches, 3));
  return reach;
}

/// Per held-out motion, reference_droop of the reference's run (`reach.runs`; none where the
/// reference diverged).
std::vector<Droop> reference_droops(
    const Split& split, const fem::MaterialModel& reference, const ReferenceReach& reach) {
  std::vector<Droop> droops;
  for (size_t i = 0; i < reach.runs.size(); ++i) {
    sim::Scene scene = split.validation[i].motion.scene;
    scene.material = reference;
    droops.push_back(reference_droop(scene, reach.runs[i]));
  }
  return droops;
}

/// `material` (the nominal of candidate c) with c's correction, in the held-out motion's scene.
sim::Scene with_candidate(
    const HeldOut& piece, const fem::MaterialModel& nominal, const Candidate& c) {
  sim::Scene scene = piece.motion.scene;
  scene.material = nominal;
  scene.material.correction = c.correction;
  return scene;
}

/// The candidate's error on the held-out data (completed false if a simulation diverged). Each
/// motion is simulated once, whole: the run predicts its training frames too (c.training).
CandidatePredictions validate_candidate(
    Candidate& c, const Split& split, const fem::MaterialModel& nominal) {
  std::vector<ErrorSummary> errors, training_errors;
  std::vector<VecX> predictions, training_predictions;
  for (size_t i = 0; i < split.validation.size(); ++i) {
    const HeldOut& piece = split.validation[i];
    const sim::ForwardRun run = sim::simulate_positions(with_candidate(piece, nominal, c));
    c.completed = run.completed;
    if (!run.completed) {
      c.failure = piece.motion.name + ": " + run.message;
      return {};
    }
    const std::vector<VecX> compared(
        run.positions.begin() + piece.first_frame, run.positions.end());
    errors.push_back(observation_error(compared, piece.motion.observed));
    predictions.push_back(at_observed_vertices(compared, piece.motion.observed));
    const observe::Observation& trained_on = split.training[i].observed;
    const std::vector<VecX> trained_frames(
        run.positions.begin(), run.positions.begin() + trained_on.num_frames());
    training_errors.push_back(observation_error(trained_frames, trained_on));
    training_predictions.push_back(at_observed_vertices(trained_frames, trained_on));
  }
  c.validation = combined_error(errors);
  c.training = combined_error(training_errors);
  return { stacked_rows(predictions), stacked_rows(training_predictions) };
}

/// The larger-motion check of a correction candidate (Candidate::larger_motion) on every
/// held-out motion, `droops` the droop loads and the reference's equilibria under them per motion
/// (none past its end).
void check_candidate_larger_motion(Candidate& c, const Split& split,
    const fem::MaterialModel& nominal, const std::vector<Droop>& droops) {
  const Droop none;
  for (size_t i = 0; i < split.validation.size(); ++i) {
    const HeldOut& piece = split.validation[i];
    // The first substepped frame of the first motion that needed substeps is kept.
    const int substepped = c.larger_motion.first_substepped_frame;
    const Droop& droop = i < droops.size() ? droops[i] : none;
    c.larger_motion = check_larger_motion(with_candidate(piece, nominal, c), piece.motion.name,
        droop.acceleration, droop.reference_equilibrium);
    if (substepped > 0)
      c.larger_motion.first_substepped_frame = substepped;
    if (!c.larger_motion.completed)
      break;
  }
}

/// "; failed in <the motion driven 1.5× as hard, or its droop> (...): not eligible" when the
/// larger-motion check failed, else "".
std::string describe_larger_motion(const LargerMotionCheck& larger) {
  if (larger.completed)
    return {};
  return "; failed in " + larger.message + ": not eligible";
}

/// "; unstable at N of M stretches a motion of another kind may reach (...): not eligible" or "".
std::string describe_instability(const StabilityReport& stability) {
  if (stability.stable())
    return {};
  return "; " + describe_unstable(stability, "stretches a motion of another kind may reach")
      + ": not eligible";
}

void say(const RecipeCallbacks& callbacks, const std::string& line) {
  if (callbacks.message)
    callbacks.message(line);
}

std::string format(const char* pattern, double a, double b = 0, double c = 0, double d = 0) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, a, b, c, d);
  return text;
}

} // namespace

/// Stages 0 and 1: σ (given or estimated), the split into training and held-out data, and the
/// training positions smoothed to σ. Sets result.noise and the frame counts.
Split prepare_data(std::span<const Motion> motions, const RecipeOptions& options,
    RecipeResult& result, const RecipeCallbacks& callbacks, double size) {
  // Stage 0: the noise.
  if (options.noise >= 0) {
    result.noise.sigma = options.noise;
    result.noise.estimated = false;
  } else {
    double sum = 0;
    long weight = 0;
    for (const Motion& m : motions) {
      const double s = observe::estimate_noise(m.observed);
      const long n = m.observed.num_valid();
      sum += s * s * static_cast<double>(n);
      weight += n;
    }
    result.noise.sigma = weight > 0 ? std::sqrt(sum / static_cast<double>(weight)) : 0;
  }

  // Stage 1: training and validation data. The smoother is global in time, so it runs on the
  // training frames alone: smoothing a whole motion would carry the held-out frames into the
  // training positions near the split.
  Split split = split_motions(motions, options.validation_fraction);
  double change = 0;
  for (Motion& m : split.training) {
    auto s = observe::smooth_to_noise(m.observed, result.noise.sigma);
    change = std::max(change, s.rms_change);
    m.smoothed = std::make_shared<const observe::Observation>(std::move(s.smoothed));
  }
  result.noise.smoothing_residual = change;
  say(callbacks,
      format("noise: σ = %.3g m (%.3f %% of the size, ", result.noise.sigma,
          100 * result.noise.sigma / size)
          + (result.noise.estimated ? "estimated" : "given")
          + "); training positions smoothed in time by " + format("%.3g m RMS", change));
  result.training_frames = split.training.front().scene.frames;
  result.validation_frames = 0;
  long seen = 0;
  for (const HeldOut& piece : split.validation) {
    result.validation_frames += piece.motion.observed.num_frames();
    seen += piece.motion.observed.num_valid();
  }
  if (seen == 0)
    throw InputError(split.validation.front().motion.name,
        "/observed/valid: no observed vertex is seen in the held-out frames (" + split.description
            + "), so no candidate can be validated");
  result.validation_data = split.description;
  say(callbacks, "validation: " + split.description);

  return split;
}

RecipeResult learn_material(std::span<const Motion> motions, const RecipeOptions& options,
    const RecipeCallbacks& callbacks, const RecipeResume* resume) {
  const auto start = Clock::now();
  options.validate();
  if (motions.empty())
    throw InputError("training set", "no motion to learn from");
  for (const Motion& m : motions) {
    m.scene.validate();
    if (m.scene.material.correction)
      throw InputError(m.name, "the nominal material must not carry a correction already");
    if (!m.captured)
      m.observed.validate(m.scene.mesh.num_vertices(), m.scene.frames + 1, m.scene.dt, m.name);
  }
  RecipeResult result;
  const fem::MaterialModel& given = motions.front().scene.material;
  const NominalParameters given_parameters = nominal_parameters_of(given, result.nominal_type);
  const double size = motions.front().scene.mesh.bounding_box_diagonal();

  // Stage −1: observations of the point-cloud captures, tracked with the given nominal (with the
  // nominal of the first fit when resuming: the tracking the loop followed).
  std::vector<Motion> learned_from(motions.begin(), motions.end());
  const bool clouds = std::any_of(learned_from.begin(), learned_from.end(),
      [](const Motion& m) { return m.captured != nullptr; });
  // The nominal material with parameters p.
  const auto nominal_with = [&](const NominalParameters& p) {
    return scene_with_parameters(motions.front().scene, result.nominal_type, p).material;
  };
  const auto observe_captures = [&](const NominalParameters& p, const char* which) {
    const fem::MaterialModel material = nominal_with(p);
    for (Motion& m : learned_from)
      if (m.captured)
        say(callbacks,
            "clouds of " + m.name + " tracked with the " + which + " nominal: "
                + observe_cloud_motion(m, material, callbacks.loop.progress).describe());
  };
  const std::optional<NominalParameters> resumed_tracking
      = resume ? resume->parameter_fit.tracked_with : std::nullopt;
  if (clouds)
    observe_captures(
        resumed_tracking.value_or(given_parameters), resumed_tracking ? "first fit's" : "given");

  // Stages 0 and 1.
  Split split = prepare_data(learned_from, options, result, callbacks, size);

  // Stage 2: the nominal model's parameters, fitted to every training motion as recorded.
  const auto fit_from = [&](const NominalParameters& start) {
    ParameterFitReport f
        = fit_parameters(split.training, result.nominal_type, start, options.parameter_fit, {});
    say(callbacks,
        format("parameter fit: E %.4g Pa, ν %.3f, α₀ %.3g 1/s, ", f.fitted.young, f.fitted.poisson,
            f.fitted.alpha0)
            + format("α₁ %.3g s; training error rms %.4f %% -> %.4f %% ", f.fitted.alpha1,
                100 * f.initial_rms / size, 100 * f.final_rms / size)
            + format("(%.0f iterations, %.0f simulations, %.1f s)", f.iterations, f.simulations,
                f.seconds));
    return f;
  };
  if (resume) {
    result.parameter_fit = resume->parameter_fit;
    result.loop = resume->loop;
  } else if (options.fit_parameters) {
    result.parameter_fit = fit_from(given_parameters);
    // Where no camera sees the surface the tracked mesh follows the material it was tracked
    // with, which biases the fit toward the given nominal: track again with the fitted nominal,
    // closer to the truth, redo stages 0 and 1 and fit again (from the given nominal, as the
    // first: a first fit gone astray on uninformative data must not be the start).
    if (clouds) {
      const ParameterFitReport first = result.parameter_fit;
      observe_captures(first.fitted, "fitted");
      split = prepare_data(learned_from, options, result, callbacks, size);
      result.parameter_fit = fit_from(given_parameters);
      result.parameter_fit.tracked_with = first.fitted;
      result.parameter_fit.initial = first.initial;
      result.parameter_fit.initial_rms = first.initial_rms;
      result.parameter_fit.initial_max = first.initial_max;
      result.parameter_fit.seconds += first.seconds;
    }
  } else {
    result.parameter_fit.initial = result.parameter_fit.fitted = given_parameters;
  }
  if (!resume && callbacks.parameters_fitted)
    callbacks.parameters_fitted(result.parameter_fit);
  result.fitted_nominal = nominal_with(result.parameter_fit.fitted);
  for (const Motion& m : learned_from)
    result.observed.push_back(m.observed);

  // Stage 3: the loop (and its forward fit) on the fitted nominal over every training motion:
  // its space-time stages follow the smoothed positions, its forward errors and forward fit
  // compare with the recorded ones.
  for (Motion& m : split.training)
    m.scene.material = result.fitted_nominal;
  // The forward fit's steps must be stable where the validation will require it, else its last
  // step, the main candidate, is not eligible and its steps were spent for nothing.
  const fem::MaterialModel& reference_material
      = options.fit_parameters ? result.fitted_nominal : given;
  const ReferenceReach reach = reference_reach(
      split, reference_material, options.loop.stretch_samples, callbacks.loop.progress);
  const MatX& reachable = reach.stretches;
  LearningOptions loop_options = options.loop;
  loop_options.forward_fit.stability_stretches = reachable;
  loop_options.forward_fit.noise = result.noise.sigma; // its tolerance measures above the noise
  // Δα₀ gives back mass damping the parameter fit put into the nominal, with the neo-Hookean
  // tail to carry the elasticity that damping stood in for (docs/learning_recipe.md, "The
  // nominal's damping, learned with the correction"). With α₀ = 0 there is none to give back:
  // a negative Δα₀ is clamped away in the simulation (α₀ + Δα₀ ≥ 0) while the fits' linear
  // column still counts it, and the tail alone learned worse as often as better, so the
  // correction is learned as before.
  if (!(result.parameter_fit.fitted.alpha0 > 0)) {
    loop_options.rbf.mass_damping = false;
    loop_options.rbf.neo_hookean_tail = false;
  }
  // Stage 4's validation, set up before the loop: the loop's candidates are validated when it
  // ends (they choose where the forward fit starts), the forward fit's after it.
  ComparedData held_out, trained; // per candidate, at_observed_vertices
  // The unknowns the loop's design fitted for an RBF correction (a network takes its teacher's).
  const auto fitted_unknowns = [&](const material::Correction* correction) {
    const auto* rbf = dynamic_cast<const material::RbfCorrection*>(correction);
    return rbf ? RbfDesign(rbf->parameters().centres, loop_options.rbf, rbf->parameters().trusted)
                     .num_unknowns()
               : 0;
  };
  const auto nominal_of = [&](CandidateKind kind) -> const fem::MaterialModel& {
    return kind == CandidateKind::Nominal ? given : result.fitted_nominal;
  };
  const auto label_of = [&](const Candidate& c) {
    std::string label = "candidate " + to_string(c.kind);
    if (c.iteration >= 0) // append, not " " + to_string(): GCC 12 warns -Wrestrict on that wrongly
      label.append(" ").append(std::to_string(c.iteration));
    return label;
  };
  /// A candidate to validate: its kind, iteration and correction.
  struct Proposed {
    CandidateKind kind;
    int iteration;
    std::shared_ptr<const material::Correction> correction;
  };
  // Validates every proposed candidate, side by side (each simulation is mostly serial on 2
  // cores), then records them in order: predictions, and the line `learn` prints.
  const auto add_all = [&](const std::vector<Proposed>& proposed) {
    std::vector<Candidate> validated(proposed.size());
    std::vector<CandidatePredictions> predictions(proposed.size());
    tbb::parallel_for(size_t { 0 }, proposed.size(), [&](size_t i) {
      Candidate& c = validated[i];
      c.kind = proposed[i].kind;
      c.iteration = proposed[i].iteration;
      c.correction = proposed[i].correction;
      const fem::MaterialModel& material = nominal_of(c.kind);
      c.unknowns = fitted_unknowns(c.correction.get());
      predictions[i] = validate_candidate(c, split, material);
      if (c.correction && c.completed)
        c.stability = material_stability(*material.elastic, c.correction.get(), reachable);
    });
    for (size_t i = 0; i < proposed.size(); ++i) {
      Candidate& c = validated[i];
      held_out.predictions.push_back(std::move(predictions[i].held_out));
      trained.predictions.push_back(std::move(predictions[i].training));
      std::string label = label_of(c);
      if (c.correction && c.correction->mass_damping() != 0) // the damping it learned
        label.append(format(" (Δα₀ %+.3g 1/s)", c.correction->mass_damping()));
      say(callbacks,
          label
              + (c.completed ? format(": validation error rms %.4f %%, max %.4f %%",
                     100 * c.validation.rms / size, 100 * c.validation.max / size)
                             : ": its simulation of the held-out data diverged (" + c.failure + ")")
              + describe_instability(c.stability));
      result.candidates.push_back(std::move(c));
    }
  };
  // The larger-motion check costs a simulation of every motion driven harder and a static solve,
  // so it runs only on a correction the choice would take (and the droop loads are computed for
  // the first such): the candidates that rank below the chosen one are not checked.
  std::optional<std::vector<Droop>> droops;
  const auto check = [&](Candidate& c) {
    if (!droops)
      droops = reference_droops(split, reference_material, reach);
    check_candidate_larger_motion(c, split, nominal_of(c.kind), *droops);
    say(callbacks,
        label_of(c)
            + (c.larger_motion.completed ? format(
                   ": survives its motions driven %.3g× as hard and their droops", kLargerMotion)
                                         : describe_larger_motion(c.larger_motion)));
  };
  // The nominals and the loop's corrections with the lowest training errors (each validation
  // costs a simulation of the held-out data); once, when the loop ends (or, in a run resumed
  // during the forward fit, in stage 4).
  bool loop_validated = false;
  const auto validate_loop = [&] {
    std::vector<Proposed> proposed { { CandidateKind::Nominal, -1, nullptr } };
    if (options.fit_parameters)
      proposed.push_back({ CandidateKind::FittedNominal, -1, nullptr });
    std::vector<const IterationRecord*> loop_records;
    for (const auto& r : result.loop.history) {
      const auto it = result.loop.tried.find(iteration_of(r));
      if (it != result.loop.tried.end() && it->second && !forward_fit_of(r)
          && forward_of(r).completed())
        loop_records.push_back(&r);
    }
    std::sort(loop_records.begin(), loop_records.end(),
        [](const IterationRecord* a, const IterationRecord* b) {
          return forward_of(*a).error().rms < forward_of(*b).error().rms;
        });
    loop_records.resize(std::min(loop_records.size(), kLoopCandidates));
    for (const IterationRecord* r : loop_records)
      proposed.push_back(
          { CandidateKind::Loop, iteration_of(*r), result.loop.tried.at(iteration_of(*r)) });
    add_all(proposed);
    loop_validated = true;
  };
  const int reference = options.fit_parameters ? 1 : 0;
  // The forward fit starts from the loop's best correction (the lowest training error) only if
  // it also predicts the held-out data better than no correction (the reference: the fitted
  // nominal); otherwise from no correction. A loop correction that trains better and validates
  // worse has fitted the training's noise or its particular stretches, and the forward fit
  // would spend its steps undoing that (quick sparse-6 at σ = 0.1 % of the size: the loop's
  // best trained at 0.2794 % RMS against the fit's 0.2920 % and validated at 0.8909 % against
  // 0.6237 %).
  LearningCallbacks loop_callbacks = callbacks.loop;
  loop_callbacks.forward_fit_start = [&](const LearningState& loop) {
    validate_loop();
    const auto& candidates = result.candidates;
    const auto best = std::find_if(candidates.begin(), candidates.end(), [&](const Candidate& c) {
      return c.kind == CandidateKind::Loop && c.iteration == loop.best_iteration;
    });
    const Candidate& none = candidates[static_cast<size_t>(reference)];
    if (best == candidates.end() || !none.completed
        || (best->completed && best->validation.rms <= none.validation.rms))
      return loop.best_iteration;
    say(callbacks,
        "the forward fit starts from no correction: the loop's best (iteration "
            + std::to_string(loop.best_iteration) + ") validates worse than the "
            + to_string(none.kind));
    return 0;
  };
  if (!run_learning(split.training, loop_options, result.loop, loop_callbacks)) {
    result.interrupted = true;
    return result;
  }

  // Stage 4: every candidate on the held-out data.
  if (!loop_validated)
    validate_loop();
  const auto& tried = result.loop.tried;
  std::vector<const IterationRecord*> forward_fit_steps;
  for (const auto& r : result.loop.history) {
    const auto it = tried.find(iteration_of(r));
    if (it != tried.end() && it->second && forward_fit_of(r) && forward_of(r).completed())
      forward_fit_steps.push_back(&r);
  }
  // The forward fit's last accepted step, and every earlier one on its plateau (a training
  // error within kPlateau of the last's): there the steps no longer learn much from the
  // training data, can fit its noise, and the held-out data choose where the fit stops (quick
  // turtle at σ = 0.1 % of the size: its last step trained at 0.1736 % RMS, validated at
  // 0.1800 % against the one before's 0.1738 / 0.1770 % and tested 4.5× worse; noisy dragon:
  // every step within 0.3 % of the fit). Steps that still learn are not validated: there the
  // held-out tail ranks them no better than chance for another motion (noise-free, validating
  // the last three chose the quick turtle's 14th step by 0.0329 against 0.0340 %, training
  // 0.0120 against the last's 0.0066 %, which tests 2× worse). A plateau measured against the
  // noise's level instead (√3 σ) hangs on the estimate of σ: the turtle's steps sat 0.3 % above it.
  const double plateau = forward_fit_steps.empty()
      ? 0.0
      : (1 + kPlateau) * forward_of(*forward_fit_steps.back()).error().rms;
  std::vector<Proposed> proposed;
  for (const IterationRecord* step : forward_fit_steps)
    if (forward_of(*step).error().rms <= plateau)
      proposed.push_back(
          { CandidateKind::ForwardFit, iteration_of(*step), tried.at(iteration_of(*step)) });
  // A run resumed from a checkpoint older than LearningState::tried knows the earlier
  // iterations only through the best one.
  if (result.loop.best && !tried.contains(result.loop.best_iteration))
    proposed.push_back({ CandidateKind::Loop, result.loop.best_iteration, result.loop.best });
  add_all(proposed);
  std::vector<VecX> held_out_observed, trained_observed;
  for (const HeldOut& piece : split.validation)
    held_out_observed.push_back(flat_positions(piece.motion.observed));
  for (const Motion& m : split.training)
    trained_observed.push_back(flat_positions(m.observed));
  held_out.observed = stacked_rows(held_out_observed);
  trained.observed = stacked_rows(trained_observed);
  result.chosen = choose_checked_candidate(
      result.candidates, held_out, trained, reference, result.noise.sigma, check);
  if (result.chosen < 0)
    throw InputError(split.validation.front().motion.name,
        "no candidate, not even the nominal material, simulates the held-out data");

  // Stage 5: the chosen RBF distilled into the network, on the first training motion (its
  // material is the fitted nominal), validated like the others.
  const auto* teacher
      = dynamic_cast<const material::RbfCorrection*>(result.choice().correction.get());
  if (options.network.enabled && teacher) {
    const int t = result.chosen;
    result.network = distil_network(split.training.front().scene, *teacher, options.network);
    say(callbacks, result.network->describe());
    add_all({ { CandidateKind::Network, result.candidates[static_cast<size_t>(t)].iteration,
        result.network->correction } });
    Candidate& network = result.candidates.back();
    network.teacher = t;
    network.unknowns = result.candidates[static_cast<size_t>(t)].unknowns;
    if (network.completed) {
      const bool has_reference = result.candidates[static_cast<size_t>(reference)].completed;
      if (has_reference)
        compare_with_reference(result.candidates, result.candidates.size() - 1, reference, held_out,
            trained, result.noise.sigma,
            result.candidates[static_cast<size_t>(t)].required_significance);
      network.gain_over_teacher = paired_significance(held_out.predictions[static_cast<size_t>(t)],
          held_out.predictions.back(), held_out.observed, result.noise.sigma);
      const auto replaces = [&] {
        return network_replaces_teacher(
            network, result.candidates[static_cast<size_t>(t)], has_reference);
      };
      if (replaces()) {
        check(network);
        if (replaces())
          result.chosen = static_cast<int>(result.candidates.size()) - 1;
      }
    }
  }
  result.seconds = seconds_since(start);
  return result;
}

} // namespace elastolearn::learn
