// elastolearn learn scene.json --observations obs.h5 -o learned.json [--report DIR] [--resume] ...
// Learn a correction of the scene's (nominal) material from observed vertex trajectories
// (paper 000 §3–§6; docs/learning.md). Checkpoints after every iteration; --resume continues.
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/interrupt.hpp>
#include <elastolearn/io/learned_material.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/io/learning_report.hpp>
#include <elastolearn/io/learning_run_report.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/report_builder.hpp>
#include <elastolearn/io/report_resources.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/training_set.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

namespace {

struct LearnOptions {
  std::string scene, observations, clouds, output, report, checkpoint, truth_material;
  bool resume = false;
  bool quiet = false;
  std::string reconstruction = "normal_equations";
  std::string continuation = "bounded_softening";
  bool no_damping = false;
  bool linear_tail = false;
  bool no_parameter_fit = false;
  bool no_backtrack = false;
  bool no_stability_cuts = false;
  std::string network_kind = "auto";
  elastolearn::learn::RecipeOptions recipe;
};

/// One line per forward-fit step (the learning's progress table).
void print_forward_fit_step(const elastolearn::learn::ForwardFitRecord& r, double diagonal) {
  using elastolearn::learn::ForwardStatus;
  const auto& f = r.forward;
  switch (f.status()) {
  case ForwardStatus::completed:
    std::printf("%4d %12.4f %12.4f %14s %6s %6d %9.2f   (forward fit: %s)\n", r.iteration,
        100 * f.error().rms / diagonal, 100 * f.error().max / diagonal, "-", "-", r.centres,
        f.seconds(), r.accepted ? "step accepted" : "step rejected, μ × 10");
    break;
  case ForwardStatus::unstable:
    std::printf(
        "%4d  forward fit: trial step rejected, μ × 10 (%s)\n", r.iteration, f.message().c_str());
    break;
  case ForwardStatus::diverged:
    std::printf("%4d  forward fit: the trial step's simulation diverged (rejected, μ × 10): %s\n",
        r.iteration, f.message().c_str());
    break;
  }
}

/// One line per loop iteration (the learning's progress table), two when the reconstructed
/// correction had to be shrunk to stay stable.
void print_loop_iteration(const elastolearn::learn::LoopRecord& r, double diagonal) {
  const auto& f = r.forward;
  if (!f.completed()) {
    std::printf(r.damped_update()
            ? "%4d  forward simulation diverged (%s): trying half of this correction's step\n"
            : "%4d  forward simulation diverged (%s): stopping (the best correction so far is "
              "kept)\n",
        r.iteration, f.message().c_str());
  } else if (const auto* t = r.stages()) {
    std::printf("%4d %12.4f %12.4f %14.4e %6d %6d %9.2f   (forward %.1f, constrained %.1f, "
                "space-time %.1f [%d it], reconstruction %.1f)\n",
        r.iteration, 100 * f.error().rms / diagonal, 100 * f.error().max / diagonal,
        t->control_force_rms, t->modes, t->centres, f.seconds() + t->seconds(), f.seconds(),
        t->seconds_constrained, t->seconds_space_time, t->space_time_iterations,
        t->seconds_reconstruction);
    if (t->stability_cuts > 0)
      std::printf(
          "      the reconstruction was held stable by %d stability cuts\n", t->stability_cuts);
    if (t->step_kept < 1)
      std::printf("      the reconstructed correction is unstable within the training stretches "
                  "(smallest tangent eigenvalue %.2f × the nominal's): %s\n",
          t->stability,
          t->step_kept > 0 ? ("kept " + elastolearn::to_text(t->step_kept) + " of it").c_str()
                           : "dropped it (the next iteration simulates the nominal)");
  } else {
    std::printf("%4d %12.4f %12.4f %14s %6s %6s %9.2f   (%s)\n", r.iteration,
        100 * f.error().rms / diagonal, 100 * f.error().max / diagonal, "-", "-", "-", f.seconds(),
        r.damped_update() ? "no better than the best: trying half of this correction's step"
                          : "last forward check");
  }
}

void print_iteration(const elastolearn::learn::IterationRecord& r, double diagonal) {
  if (const auto* step = elastolearn::learn::forward_fit_of(r))
    print_forward_fit_step(*step, diagonal);
  else
    print_loop_iteration(std::get<elastolearn::learn::LoopRecord>(r), diagonal);
  std::fflush(stdout);
}

void run_learn(const LearnOptions& o) {
  using namespace elastolearn;
  if (!o.truth_material.empty() && o.report.empty())
    throw InputError("--truth-material", "is used by the report only: give --report DIR too");
  const io::TrainingSet set
      = io::read_learning_data(o.scene, o.observations, "--observations", o.clouds, "--clouds");
  const std::filesystem::path checkpoint = io::learning_checkpoint_path(o.output, o.checkpoint);
  {
    // With --resume the checkpoint is read and then rewritten on purpose: it is an output only.
    std::vector<CommandOutput> outputs
        = { { o.output, "learned material output (-o)" }, { checkpoint, "checkpoint" } };
    std::vector<CommandInput> inputs = set.inputs;
    if (!o.truth_material.empty())
      inputs.push_back({ o.truth_material, "true material (--truth-material)" });
    if (!o.report.empty()) {
      for (CommandOutput& output : io::report_outputs(o.report, "--report folder"))
        outputs.push_back(std::move(output));
      io::report_resource_dir(); // throws now, not after the work, if the report cannot be made
    }
    check_command_paths(inputs, outputs);
  }
  // Read before learning, so that a bad file stops the command before it does any work.
  std::optional<fem::MaterialModel> truth;
  if (!o.truth_material.empty())
    truth = io::material_model(io::read_material_file(o.truth_material), o.truth_material);
  const std::vector<learn::Motion>& motions = set.motions;
  const sim::Scene& scene = motions.front().scene;

  learn::RecipeOptions options = o.recipe;
  learn::LearningOptions& loop = options.loop;
  loop.reconstruction.method
      = learn::reconstruction_method_from_name(o.reconstruction, "--reconstruction");
  loop.rbf.continuation = material::continuation_from_name(o.continuation, "--continuation");
  loop.rbf.fit_damping = !o.no_damping;
  loop.rbf.quadratic_tail = !o.linear_tail;
  options.fit_parameters = !o.no_parameter_fit;
  if (o.no_backtrack)
    loop.backtrack = false;
  if (o.no_stability_cuts) {
    loop.stability_cuts = false;
    loop.forward_fit.stability_cuts = false;
  }
  options.network.kind = learn::network_kind_from_name(o.network_kind, "--network-kind");
  options.validate();

  const io::LearningInputs inputs { o.scene, o.observations.empty() ? o.clouds : o.observations,
    io::recipe_options_to_json(options) };
  std::optional<learn::RecipeResume> resume;
  if (o.resume) {
    resume = io::resume_learning_checkpoint(checkpoint, inputs, "--resume");
    std::printf("resuming from %s at iteration %d\n", checkpoint.string().c_str(),
        resume->loop.next_iteration);
  }
  for (const learn::Motion& m : motions) {
    if (m.captured) {
      std::printf("learning from %s: %d vertices, %d tets, %d frames of dt = %g s, point clouds "
                  "of %lld points in all, nominal %s\n",
          m.name.c_str(), m.scene.mesh.num_vertices(), m.scene.mesh.num_tets(), m.scene.frames,
          m.scene.dt, static_cast<long long>(m.captured->clouds.num_points()),
          m.scene.material.elastic->name().c_str());
      continue;
    }
    const std::string lost = observe::describe_lost_entries(m.observed);
    std::printf("learning from %s: %d vertices, %d tets, %d frames of dt = %g s, %d observed "
                "vertices%s, nominal %s\n",
        m.name.c_str(), m.scene.mesh.num_vertices(), m.scene.mesh.num_tets(), m.scene.frames,
        m.scene.dt, m.observed.num_observed(), lost.empty() ? "" : (" (" + lost + ")").c_str(),
        m.scene.material.elastic->name().c_str());
  }
  std::fflush(stdout);
  const double diagonal = scene.mesh.bounding_box_diagonal();

  learn::RecipeCallbacks callbacks;
  learn::ParameterFitReport fitted = resume ? resume->parameter_fit : learn::ParameterFitReport {};
  callbacks.message = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  callbacks.parameters_fitted = [&](const learn::ParameterFitReport& f) {
    fitted = f;
    std::printf("%4s %12s %12s %14s %6s %6s %9s\n", "iter", "err rms [%]", "err max [%]",
        "control [N]", "modes", "kernels", "time [s]");
  };
  if (!o.quiet)
    callbacks.loop.progress = terminal_progress("learn");
  callbacks.loop.interrupted = [] { return interrupt_requested(); };
  callbacks.loop.iteration = [&](const learn::IterationRecord& r) { print_iteration(r, diagonal); };
  callbacks.loop.checkpoint = [&](const learn::LearningState& s) {
    io::write_learning_checkpoint(checkpoint, inputs, { fitted, s });
  };

  const learn::RecipeResult result
      = learn::learn_material(motions, options, callbacks, resume ? &*resume : nullptr);
  if (result.interrupted) {
    std::fprintf(stderr,
        "elastolearn: interrupted; resume with the same command and --resume (checkpoint %s)\n",
        checkpoint.string().c_str());
    throw CLI::RuntimeError(130);
  }

  const learn::Candidate& chosen = result.choice();
  const io::MaterialFile learned = io::learned_material_file(set, o.scene, result, options);
  io::write_material_file(o.output, learned);

  std::printf("validation on %s (error rms, %% of the size %.4g m):\n",
      result.validation_data.c_str(), diagonal);
  for (size_t i = 0; i < result.candidates.size(); ++i) {
    const auto& c = result.candidates[i];
    const std::string name = learn::to_string(c.kind)
        + (c.iteration < 0
                ? ""
                : (c.kind == learn::CandidateKind::Network ? " (from iteration " : " (iteration ")
                    + std::to_string(c.iteration) + ")");
    const bool reference = c.kind == learn::CandidateKind::FittedNominal
        || (c.kind == learn::CandidateKind::Nominal && !options.fit_parameters);
    std::string note;
    if (static_cast<int>(i) == result.chosen)
      note = "   <- chosen"
          + (c.correction && c.correction->mass_damping() != 0
                  ? " (with Δα₀ " + elastolearn::to_text(c.correction->mass_damping())
                      + " 1/s on the nominal's mass damping)"
                  : std::string());
    else if (c.completed && !c.eligible())
      note = "   (not eligible: "
          + (c.larger_motion.completed ? std::string("unstable where another motion may go")
                                       : "failed in " + c.larger_motion.message)
          + ")";
    else if (c.completed && c.kind == learn::CandidateKind::Network && c.teacher == result.chosen)
      note = "   (" + elastolearn::to_text(-c.gain_over_teacher) + " noise deviations and "
          + elastolearn::to_text(
              100 * (c.validation.rms / result.candidates[c.teacher].validation.rms - 1))
          + " % worse than its teacher: the RBF is kept)";
    else if (c.completed && !reference && c.resolution < c.required_significance)
      note = "   (the held-out data cannot tell it from the fitted nominal; on the training data "
          + (std::isnan(c.training_significance)
                  ? std::string("not compared")
                  : "better by " + elastolearn::to_text(c.training_significance)
                      + " noise deviations after its unknowns' share")
          + ": hold out frames that still move, e.g. a second motion, to let them decide)";
    else if (c.completed && !reference && c.significance <= 0)
      note = "   (no better than the fitted nominal)";
    else if (c.completed && !reference && c.significance < c.required_significance)
      note = "   (better than the fitted nominal by " + elastolearn::to_text(c.significance)
          + " noise deviations: not significant)";
    if (c.completed)
      std::printf(
          "  %-28s %10.4f %%%s\n", name.c_str(), 100 * c.validation.rms / diagonal, note.c_str());
    else
      std::printf("  %-28s   diverged\n", name.c_str());
  }
  std::printf("learned material: %s (%s%s); %.1f s in total\n", o.output.c_str(),
      learn::to_string(chosen.kind).c_str(),
      learned.correction ? (", " + io::describe_correction(*learned.correction)).c_str() : "",
      result.seconds);
  if (learned.training_stretches)
    std::printf("training stretches: %s (simulate and evaluate note where a motion leaves them)\n",
        learn::describe(*learned.training_stretches).c_str());
  if (!o.report.empty()) {
    std::printf("report: simulating the candidates on %s for the plots\n", motions[0].name.c_str());
    std::fflush(stdout);
    const io::LearningRunReportInputs report { o.scene, o.output, motions, &result, &learned,
      truth ? &*truth : nullptr, o.truth_material };
    std::printf("%s\n",
        io::describe_report(o.report, io::write_learning_run_report(o.report, report)).c_str());
  }
}

void add_learn_command(CLI::App& root) {
  auto o = std::make_shared<LearnOptions>();
  auto* cmd = root.add_subcommand(
      "learn", "Learn a material correction from observed vertex trajectories or point clouds");
  cmd->add_option("scene", o->scene,
         "scene with the nominal material (elastolearn-scene/1 JSON), or a training set of "
         "several motions (elastolearn-training/1 JSON)")
      ->required();
  cmd->add_option("--observations", o->observations,
      "observation HDF5 of the scene's motion (from observe, or your capture); not with a "
      "training set");
  cmd->add_option("--clouds", o->clouds,
      "point-cloud HDF5 of the scene's motion instead (from scan or import-clouds): tracked, "
      "then learned from (docs/tracking.md); not with a training set");
  cmd->add_option("-o,--output", o->output, "learned material JSON to write")->required();
  cmd->add_option("--report", o->report,
      "folder for the report: report.html (plots, animation; opens offline), summary.json, "
      "convergence.csv, report.json (docs/report.md)");
  cmd->add_option("--truth-material", o->truth_material,
      "the true material (elastolearn-material/1 JSON), when known: the report plots the learned "
      "correction and damping against it");
  cmd->add_option(
      "--checkpoint", o->checkpoint, "checkpoint file (default: OUTPUT.checkpoint.json)");
  cmd->add_flag("--resume", o->resume, "continue from the checkpoint");
  auto& l = o->recipe.loop;
  cmd->add_option("--noise", o->recipe.noise,
         "observation noise σ [m] per coordinate (default: estimated from the data)")
      ->capture_default_str();
  cmd->add_option("--validation-fraction", o->recipe.validation_fraction,
         "fraction of every motion's frames, at its end, held out to choose the material")
      ->capture_default_str();
  cmd->add_flag("--no-parameter-fit", o->no_parameter_fit,
      "learn on the scene's nominal parameters as given (default: fit E, ν, α₀, α₁ first)");
  cmd->add_option("--parameter-fit-iterations", o->recipe.parameter_fit.max_iterations,
         "Levenberg-Marquardt iterations of the parameter fit")
      ->capture_default_str();
  cmd->add_option("--max-iterations", l.max_iterations, "corrections computed at most")
      ->capture_default_str();
  cmd->add_option("--patience", l.patience, "stop after this many iterations without improvement")
      ->capture_default_str();
  cmd->add_option("--free-halvings", l.free_halvings,
         "failed corrections in a row (diverged, or no better than the best when backtracking) "
         "halved towards the best one before patience counts them")
      ->capture_default_str();
  cmd->add_flag("--no-backtrack", o->no_backtrack,
      "run the loop's stages from a correction that is no better than the best (paper §3) "
      "instead of halving it towards the best");
  cmd->add_flag("--no-stability-cuts", o->no_stability_cuts,
      "keep a correction stable only by shrinking it (the loop) or shortening and rejecting a "
      "step (the forward fit), without solving its fit subject to stability cuts");
  cmd->add_option("--modes", l.pod.max_modes, "POD modes r of the space-time optimisation")
      ->capture_default_str();
  cmd->add_option("--pod-stride", l.pod.frame_stride, "use every k-th frame for POD")
      ->capture_default_str();
  cmd->add_flag("--full-space", l.full_space, "no reduction (Φ = identity): small meshes only");
  cmd->add_flag("!--pod-forward-only", l.pod_with_constrained,
      "POD of the forward simulation only (default: also of the constrained one)");
  cmd->add_option("--kernels", l.centres, "RBF kernels (k-means centres)")->capture_default_str();
  cmd->add_option(
         "--position-weight", l.space_time.position_weight, "λ of the position term (Eq. 4)")
      ->capture_default_str();
  cmd->add_option("--space-time-iterations", l.space_time.max_iterations,
         "Gauss-Newton iterations per space-time solve")
      ->capture_default_str();
  cmd->add_option("--regularization", l.rbf.regularization, "Tikhonov weight of the RBF fit")
      ->capture_default_str();
  cmd->add_option("--reconstruction", o->reconstruction,
         "normal_equations | lsqr (min-norm stresses, paper Fig. 4)")
      ->capture_default_str();
  cmd->add_option("--frame-stride", l.reconstruction.frame_stride,
         "use every k-th frame in the reconstruction")
      ->capture_default_str();
  cmd->add_flag("!--unprojected-reconstruction", l.projected_reconstruction,
      "fit the control forces at every free dof alike (default: mainly within the POD basis)");
  cmd->add_option("--full-space-weight", l.reconstruction.full_space_weight,
         "weight of the misfit outside the POD basis in the projected reconstruction")
      ->capture_default_str();
  cmd->add_flag("--no-damping", o->no_damping, "do not learn the damping correction");
  cmd->add_flag("--linear-tail", o->linear_tail,
      "RBF with a linear polynomial tail only (default: quadratic)");
  cmd->add_option("--damping-regularization", l.rbf.damping_regularization,
         "Tikhonov weight of the damping correction's unknowns")
      ->capture_default_str();
  cmd->add_option("--continuation", o->continuation,
         "how a correction continues beyond the stretches it was learned from: "
         "bounded_softening (the edge's stiffness, keeping half the nominal's) | "
         "smooth_expansion (exact: a second-order expansion at the ends) | smooth_clamp (exact: "
         "the ends' uniaxial stress and stiffness); docs/learning_recipe.md")
      ->check(CLI::IsMember({ "bounded_softening", "smooth_expansion", "smooth_clamp" }))
      ->capture_default_str();
  cmd->add_option("--smoothness", l.rbf.smoothness,
         "weight of the RBF's smoothness penalty (native-space seminorm of the kernel weights, "
         "relative to the data; 0 = none)")
      ->capture_default_str();
  cmd->add_option("--seed", l.seed, "k-means seed")->capture_default_str();
  cmd->add_option("--forward-fit", l.forward_fit.max_iterations,
         "Levenberg-Marquardt steps on the forward simulation's error after the loop (0 = none)")
      ->capture_default_str();
  cmd->add_option("--forward-fit-tolerance", l.forward_fit.function_tolerance,
         "forward fit: stop after an accepted step that lowers the error by less than this "
         "fraction (0 = take every step)")
      ->capture_default_str();
  cmd->add_option("--damping-prior", l.forward_fit.damping_prior,
         "forward fit: Tikhonov weight (Jacobi-scaled) pulling the damping correction towards 0")
      ->capture_default_str();
  cmd->add_option("--elastic-prior", l.forward_fit.elastic_prior,
         "forward fit: the same on the elastic correction (a large value learns the damping only)")
      ->capture_default_str();
  cmd->add_option("--kernel-smoothing", l.rbf.epsilon, "RBF kernel smoothing ε (in stretch units)")
      ->capture_default_str();
  cmd->add_flag("!--stress-kernels", l.rbf.energy_kernels,
      "RBF kernels of the principal stress (paper Eq. 10) instead of an energy's (default)");
  cmd->add_flag("!--no-neo-hookean-tail", l.rbf.neo_hookean_tail,
      "RBF without the neo-Hookean tail (barrier terms that extrapolate strong compression)");
  cmd->add_flag("!--no-mass-damping", l.rbf.mass_damping,
      "do not learn Δα₀, the change of the fitted nominal's mass damping, with the correction");
  cmd->add_flag("--damping-quadratic-tail", l.rbf.damping_quadratic_tail,
      "RBF damping Δα₁ with a quadratic tail too (carries its curvature beyond the training's "
      "stretches)");
  cmd->add_flag("!--allow-rest-stress", l.rbf.stress_free_rest,
      "let the correction carry a stress at rest (default: N(1, 1, 1) = 0)");
  auto& n = o->recipe.network;
  cmd->add_flag("!--no-network", n.enabled,
      "keep the chosen RBF (default: distil it into the network correction, which replaces it "
      "when it validates as well; the RBF then goes to training.teacher)");
  cmd->add_option("--network-kind", o->network_kind,
         "the network: energy (ΔΨ(σ), N its gradient), stress (N per direction), or auto (energy "
         "for an RBF with energy kernels)")
      ->check(CLI::IsMember({ "auto", "energy", "stress" }))
      ->capture_default_str();
  cmd->add_option("--network-motion-scales", n.motion_scales,
         "motion amplitudes simulated to sample the network's training states")
      ->capture_default_str();
  cmd->add_option(
         "--network-samples", n.samples.recorded_samples, "element states recorded for the network")
      ->capture_default_str();
  cmd->add_option("--network-rate-jitter", n.samples.rate_jitter,
         "stretch-rate jitter of the network's samples, relative to the RMS recorded rate")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "no progress line");
  cmd->callback([o] { run_learn(*o); });
}

} // namespace

ELASTOLEARN_COMMAND(35, add_learn_command)
