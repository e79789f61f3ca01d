// The learning loop end to end (paper 000 §3, issue 3 "Tests"): a small clamped bar whose truth
// is neo-Hookean is learned from a corotated nominal with the wrong stiffness (the turtle case's
// E ratio 2e4 : 3.5e4), observing every surface vertex of a droop under gravity, and evaluated on
// a different, larger motion (an upward swing). Also: truth = nominal learns ≈ nothing.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/learning_stages.hpp>
#include <elastolearn/learn/nn_distillation.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <support/bar_scene.hpp>
#include <support/learning_history.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace elastolearn::learn {
namespace {

/// A 0.4 × 0.1 × 0.1 m bar (240 tets) clamped at x = 0, 100 frames of 4 ms: elastic model `type`
/// with Young's modulus `young`, ν = 0.43, Rayleigh α₁ = 0.01 s.
test::BarOptions bar(material::ElasticModelType type, double young) {
  return { .cells = { 10, 2, 2 },
    .model = type,
    .young = young,
    .poisson = 0.43,
    .alpha1 = 0.01,
    .dt = 4e-3,
    .frames = 100 };
}

/// The bar drooping under gravity from rest or, with `swing`, also swinging up from ω = 2 rad/s.
sim::Scene bar_scene(const test::BarOptions& bar, bool swing) {
  sim::Scene s = test::bar_scene(bar);
  if (swing) {
    s.initial.kind = sim::InitialCondition::Kind::Velocity;
    s.initial.angular_velocity = Vec3(0, 0, 2.0);
  }
  return s;
}

observe::Observation observe_surface(const sim::Scene& truth) {
  const auto run = sim::simulate_positions(truth);
  EXPECT_TRUE(run.completed);
  std::vector<Positions> frames;
  for (const auto& x : run.positions)
    frames.emplace_back(unflatten(x));
  return observe::observe_vertices(
      frames, truth.dt, observe::select_visible_vertices(truth.mesh, 1.0, 1), 0.0, 1);
}

LearningOptions small_options() {
  LearningOptions o;
  o.max_iterations = 4;
  o.centres = 20;
  o.pod.max_modes = 12;
  return o;
}

/// err_L (% of the rest bounding-box diagonal) of `scene`'s swing against the truth's.
double swing_error(const sim::Scene& truth, const sim::Scene& model) {
  const auto a = sim::simulate_positions(truth), b = sim::simulate_positions(model);
  EXPECT_TRUE(a.completed && b.completed) << b.message;
  return as_percent_of(position_error(b.positions, a.positions), truth.mesh.bounding_box_diagonal())
      .max;
}

/// The corotated bar (E = 1e6 Pa) drooping for 20 frames, observed at its surface: the data of
/// a loop resumed at iteration 1 (resumed_at_iteration_1).
struct OwnDroop {
  sim::Scene scene = [] {
    auto s = bar_scene(bar(material::ElasticModelType::Corotated, 1e6), false);
    s.frames = 20;
    return s;
  }();
  observe::Observation observed = observe_surface(scene);
};

/// The neo-Hookean bar (E = 1e6 Pa) drooping for 40 frames, observed at its surface, and its
/// scene with a corotated nominal 1.75× too stiff to learn from.
struct TooStiffDroop {
  static sim::Scene droop(material::ElasticModelType type, double young) {
    sim::Scene s = bar_scene(bar(type, young), false);
    s.frames = 40;
    return s;
  }
  sim::Scene scene = droop(material::ElasticModelType::Corotated, 1.75e6);
  observe::Observation observed
      = observe_surface(droop(material::ElasticModelType::NeoHookean, 1e6));
};

/// A loop state resumed at iteration 1: C_1 a uniaxial slope `own_slope` [Pa] (no kernels), the
/// best so far the nominal (iteration 0) with forward error `best_error` [m].
LearningState resumed_at_iteration_1(double own_slope, double best_error) {
  material::RbfCorrection::Parameters p;
  p.centres.resize(0, 3);
  p.own_slope = own_slope;
  LearningState state;
  state.next_iteration = 1;
  state.correction = std::make_shared<material::RbfCorrection>(p);
  state.best_error = best_error;
  state.best_iteration = 0;
  return state;
}

TEST(LearningLoop, LearnsNeoHookeanFromAWrongCorotatedNominal) {
  const auto truth = bar(material::ElasticModelType::NeoHookean, 1e6);
  const auto nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  const auto observed = observe_surface(bar_scene(truth, false));
  LearningState state;
  ASSERT_TRUE(run_learning(bar_scene(nominal, false), observed, small_options(), state));
  ASSERT_TRUE(state.best);
  ASSERT_FALSE(state.history.empty());
  // The training fit improves by well over an order of magnitude (a stage that stops working
  // leaves it near the nominal's).
  EXPECT_LT(state.best_error, 0.05 * test::forward_rms(state.history.front()));

  const double nominal_error = swing_error(bar_scene(truth, true), bar_scene(nominal, true));
  const double learned_error = swing_error(
      bar_scene(truth, true), sim::with_correction(bar_scene(nominal, true), state.best));
  // Stored regression figures (Release build, this configuration): nominal 4.450 %, learned
  // 0.0312 % (140× lower).
  // The issue asks for ≥ 5× below the nominal; the test asserts that, and that the learned figure
  // stays within 2× of the stored one (a compiler's different rounding moves it a little; a
  // broken stage moves it by orders of magnitude).
  std::printf("[ measured ] err_L nominal %.4f %%, learned %.4f %% (best iteration %d)\n",
      nominal_error, learned_error, state.best_iteration);
  EXPECT_NEAR(nominal_error, 4.450, 0.01);
  EXPECT_LT(learned_error, nominal_error / 5);
  EXPECT_LT(learned_error, 2 * 0.0312);

  // The distilled network (paper §6.2, the recipe's stage 5): N fitted on the training motion at
  // three amplitudes, Δα₁ carried over from the teacher (distilled instead, the network's
  // simulation of the demo's test motion diverges: docs/learning.md). It must simulate the unseen
  // swing stably and stay well below the nominal error (its fit is ~1.5 % of the teacher's
  // output; stored figure 0.0435 %, the same 2× regression margin).
  DistillationSampleOptions so;
  so.recorded_samples = 10000;
  const std::vector<double> scales { 0.5, 1.0, 2.0 };
  const StressSamples samples
      = distillation_samples(bar_scene(nominal, false), scales, *state.best, so);
  const material::NnCorrection network
      = with_teacher_damping(distill_nn_correction(samples, {}).correction, *state.best);
  const double network_error = swing_error(bar_scene(truth, true),
      sim::with_correction(
          bar_scene(nominal, true), std::make_shared<material::NnCorrection>(network)));
  std::printf("[ measured ] err_L network %.4f %%\n", network_error);
  EXPECT_LT(network_error, nominal_error / 5);
  EXPECT_LT(network_error, 2 * 0.0435);
}

TEST(LearningLoop, EnergyKernelsDistilIntoAnEnergyNetwork) {
  // The recipe's correction (energy kernels) distilled into the energy network (distill_rbf on
  // the training motion's stretches at three amplitudes): the network must simulate the unseen
  // swing stably, well below the nominal error, and close to its teacher: stored figures
  // (Release build) nominal 4.450 %, RBF 0.0548 %, energy network 0.0562 % (distillation error
  // 0.04 % of the teacher's N: the teacher's tails are the network's polynomial exactly). Bounds:
  // the 2× regression margin of the test above, and within 1.5× of the teacher.
  const auto truth = bar(material::ElasticModelType::NeoHookean, 1e6);
  const auto nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  const auto observed = observe_surface(bar_scene(truth, false));
  LearningOptions options = small_options();
  options.rbf.energy_kernels = true;
  LearningState state;
  ASSERT_TRUE(run_learning(bar_scene(nominal, false), observed, options, state));
  const auto* rbf = dynamic_cast<const material::RbfCorrection*>(state.best.get());
  ASSERT_NE(rbf, nullptr);
  ASSERT_TRUE(rbf->parameters().energy_kernels);
  DistillationSampleOptions so;
  so.recorded_samples = 10000;
  so.jitter_copies = 0;
  const std::vector<double> scales { 0.5, 1.0, 2.0 };
  const StressSamples samples = distillation_samples(bar_scene(nominal, false), scales, *rbf, so);
  const RbfDistillationOptions defaults;
  const NnDistillationResult r = distill_rbf(*rbf, samples.stretches, defaults);
  ASSERT_EQ(r.correction.parameters().kind, material::NnKind::Energy);
  const double nominal_error = swing_error(bar_scene(truth, true), bar_scene(nominal, true));
  const double rbf_error = swing_error(
      bar_scene(truth, true), sim::with_correction(bar_scene(nominal, true), state.best));
  const double network_error = swing_error(bar_scene(truth, true),
      sim::with_correction(
          bar_scene(nominal, true), std::make_shared<material::NnCorrection>(r.correction)));
  std::printf("[ measured ] energy kernels: err_L nominal %.4f %%, RBF %.4f %%, energy network "
              "%.4f %% (distillation %.2f %% of the teacher's N, %d epochs)\n",
      nominal_error, rbf_error, network_error, 100 * r.relative_validation_rms(),
      r.training.epochs);
  EXPECT_LT(rbf_error, nominal_error / 5);
  EXPECT_LT(network_error, nominal_error / 5);
  EXPECT_LT(network_error, 2 * 0.0562);
  EXPECT_LT(network_error, 1.5 * rbf_error);
}

TEST(LearningLoop, FullSpaceVariantLearnsOnASmallMesh) {
  // No reduction (Φ = identity on the 72 free dofs of a 36-tet bar): the same loop, the same
  // improvement; and the variant refuses meshes too big for its dense blocks.
  auto small = [](test::BarOptions o, bool swing) {
    o.cells = { 6, 1, 1 };
    o.frames = 40;
    return bar_scene(o, swing);
  };
  const auto truth = bar(material::ElasticModelType::NeoHookean, 1e6);
  const auto nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  const auto observed = observe_surface(small(truth, false));
  LearningOptions options = small_options();
  options.full_space = true;
  options.centres = 10;
  LearningState state;
  ASSERT_TRUE(run_learning(small(nominal, false), observed, options, state));
  ASSERT_TRUE(stages_of(state.history.front()));
  EXPECT_EQ(stages_of(state.history.front())->modes, 72);
  ASSERT_TRUE(state.best);
  const double nominal_error = swing_error(small(truth, true), small(nominal, true));
  const double learned_error
      = swing_error(small(truth, true), sim::with_correction(small(nominal, true), state.best));
  std::printf("[ measured ] full space: err_L nominal %.4f %%, learned %.4f %%\n", nominal_error,
      learned_error);
  EXPECT_LT(learned_error, nominal_error / 5);

  options.max_full_space_dofs = 50;
  LearningState refused;
  EXPECT_THROW(run_learning(small(nominal, false), observed, options, refused), InputError);
}

TEST(LearningLoop, DivergingCorrectionsAreHalvedBeforePatienceCountsThem) {
  // Resume at iteration 1 with a correction whose simulation diverges: a uniaxial softening of
  // 40× the nominal's stiffness (E = 1e6 Pa), so that ½ and ¼ of it diverge as well. The first
  // `free_halvings` divergences in a row are halved without counting against patience (1 here).
  const OwnDroop data;
  const double own_slope = -40e6;
  for (const int free_halvings : { 0, 2 }) {
    LearningOptions options = small_options();
    options.patience = 1;
    options.free_halvings = free_halvings;
    // The nominal's error, say: no simulation that completes would be worse.
    LearningState state = resumed_at_iteration_1(own_slope, 1.0);
    ASSERT_TRUE(run_learning(data.scene, data.observed, options, state));
    ASSERT_EQ(state.history.size(), static_cast<size_t>(free_halvings + 1))
        << "free_halvings " << free_halvings;
    // Every correction diverged: halved (a damped update) while halvings are free, then the
    // loop ended.
    for (size_t i = 0; i < state.history.size(); ++i) {
      const auto* r = std::get_if<LoopRecord>(&state.history[i]);
      ASSERT_TRUE(r);
      EXPECT_EQ(r->forward.status(), ForwardStatus::diverged);
      EXPECT_NE(r->forward.message().find("frame"), std::string::npos) << r->forward.message();
      if (i + 1 < state.history.size())
        EXPECT_TRUE(r->damped_update()) << "step " << i;
      else
        EXPECT_TRUE(std::holds_alternative<LoopEnd>(r->next)) << "step " << i;
    }
    EXPECT_EQ(state.failed_steps_in_a_row, free_halvings + 1);
    EXPECT_EQ(state.iterations_without_improvement, 1);
    EXPECT_TRUE(state.finished);
    // The last correction tried is 2^-free_halvings of the first (the best is the nominal).
    const double scale = std::ldexp(1.0, -free_halvings);
    EXPECT_NEAR(
        state.correction->parameters().own_slope, scale * own_slope, 1e-9 * std::abs(own_slope));
  }
}

TEST(LearningLoop, BacktrackingHalvesACompletedCorrectionThatIsNoBetter) {
  // The data are the nominal's own motion, so any correction is worse than none. Resume at
  // iteration 1 with a stiffening that simulates fine: backtracking treats it as a failed step
  // (halved towards the best, no trajectory stages), without it the stages run from it.
  const OwnDroop data;
  const double own_slope = 2e6;
  for (const bool backtrack : { false, true }) {
    LearningOptions options = small_options();
    options.patience = 2;
    options.free_halvings = 1;
    options.backtrack = backtrack;
    // The nominal's error: it reproduces its own data.
    LearningState state = resumed_at_iteration_1(own_slope, 1e-12);
    ASSERT_TRUE(run_learning(data.scene, data.observed, options, state));
    ASSERT_FALSE(state.history.empty());
    const auto* first = std::get_if<LoopRecord>(&state.history.front());
    ASSERT_TRUE(first);
    EXPECT_EQ(first->forward.status(), ForwardStatus::completed);
    EXPECT_GT(first->forward.error().rms, state.best_error);
    EXPECT_EQ(state.best_iteration, 0) << "backtrack " << backtrack;
    if (!backtrack) {
      EXPECT_TRUE(first->stages()) << "the stages run from a worse correction";
      continue;
    }
    // Whole, ½ and ¼ of the step, all completed and worse: the first halving is free, the next
    // two count against patience 2.
    ASSERT_EQ(state.history.size(), 3u);
    for (size_t i = 0; i < state.history.size(); ++i) {
      const auto* r = std::get_if<LoopRecord>(&state.history[i]);
      ASSERT_TRUE(r);
      EXPECT_EQ(r->forward.status(), ForwardStatus::completed) << "step " << i;
      if (i + 1 < state.history.size())
        EXPECT_TRUE(r->damped_update()) << "step " << i;
      else
        EXPECT_TRUE(std::holds_alternative<LoopEnd>(r->next));
    }
    EXPECT_EQ(state.failed_steps_in_a_row, 3);
    EXPECT_TRUE(state.finished);
    EXPECT_NEAR(state.correction->parameters().own_slope, 0.25 * own_slope, 1e-9 * own_slope);
  }
}

TEST(LearningLoop, ANominalNoBetterThanTheNominalEndsTheLoop) {
  // A reconstruction dropped as unstable leaves C_1 = the nominal, no better than iteration 0's:
  // with the best the nominal too there is no step to halve, and the loop ends there (it once
  // dereferenced the missing correction to halve it).
  const OwnDroop data;
  for (const bool backtrack : { false, true }) {
    LearningOptions options = small_options();
    options.backtrack = backtrack;
    LearningState state = resumed_at_iteration_1(0.0, 0.0); // nothing is below 0
    state.correction = nullptr;
    ASSERT_TRUE(run_learning(data.scene, data.observed, options, state));
    ASSERT_FALSE(state.history.empty());
    const auto* first = std::get_if<LoopRecord>(&state.history.front());
    ASSERT_TRUE(first);
    EXPECT_EQ(first->forward.status(), ForwardStatus::completed);
    if (backtrack) {
      EXPECT_TRUE(std::holds_alternative<LoopEnd>(first->next));
      EXPECT_EQ(state.history.size(), 1u);
    }
    EXPECT_TRUE(state.finished);
    EXPECT_EQ(state.best_iteration, 0);
  }
}

TEST(LearningLoop, TheForwardFitKeepsTheCallersStabilitySamples) {
  // The recipe asks for stability where its validation will check the forward fit's last step
  // (around the held-out frames' stretches); the forward fit adds the samples of its own
  // motions' runs to those and must not replace them.
  const OwnDroop d;
  const Motion motion { "droop", d.scene, d.observed };
  const ReconstructionMesh mesh(d.scene.mesh, d.scene.material);
  LearningOptions options = small_options();
  const auto start = [&] {
    return forward_fit_start(std::span(&motion, 1), std::span(&mesh, 1), nullptr, options, 3, -1)
        .options.stability_stretches;
  };
  const MatX own = start();
  ASSERT_GT(own.rows(), 0);
  const MatX required = (MatX(2, 3) << 1.3, 1.0, 0.9, 0.7, 0.8, 1.1).finished();
  options.forward_fit.stability_stretches = required;
  const MatX both = start();
  ASSERT_EQ(both.rows(), own.rows() + 2);
  EXPECT_EQ(MatX(both.topRows(own.rows())), own);
  EXPECT_EQ(MatX(both.bottomRows(2)), required);
}

TEST(LearningLoop, AConvergedForwardFitStopsAndStaysStopped) {
  // A tolerance no step can meet (each accepted step would have to lower the error by 99 %):
  // the forward fit stops after its first accepted step, and running the finished state again
  // takes no further step (as a resumed run must not).
  const TooStiffDroop d;
  LearningOptions options = small_options();
  options.max_iterations = 0;
  options.forward_fit.max_iterations = 6;
  options.forward_fit.function_tolerance = 0.99;
  LearningState state;
  ASSERT_TRUE(run_learning(d.scene, d.observed, options, state));
  ASSERT_TRUE(state.forward_fit_converged);
  ASSERT_LT(state.forward_fit_steps, options.forward_fit.max_iterations);
  const ForwardFitRecord* last = forward_fit_of(state.history.back());
  ASSERT_TRUE(last);
  EXPECT_TRUE(last->accepted);
  const size_t steps = state.history.size();
  ASSERT_TRUE(run_learning(d.scene, d.observed, options, state));
  EXPECT_EQ(state.history.size(), steps);
}

TEST(LearningLoop, TheForwardFitStartsWhereTheCallerChooses) {
  // The neo-Hookean bar from a 1.75× too stiff corotated nominal: the loop's best is a learned
  // correction. A caller that sends the forward fit back to no correction (iteration 0) is asked
  // once, after the loop, and the forward fit's first trial is then the one a run without loop
  // iterations takes from the nominal, bit for bit.
  const TooStiffDroop d;
  LearningOptions options = small_options();
  options.max_iterations = 2;
  options.forward_fit.max_iterations = 1;
  const auto first_trial_rms = [](const LearningState& state) {
    for (const IterationRecord& r : state.history)
      if (forward_fit_of(r))
        return forward_of(r).error().rms;
    ADD_FAILURE() << "no forward-fit step";
    return -1.0;
  };

  LearningState from_best;
  ASSERT_TRUE(run_learning(d.scene, d.observed, options, from_best));
  int asked = 0;
  LearningCallbacks callbacks;
  callbacks.forward_fit_start = [&](const LearningState& loop) {
    ++asked;
    EXPECT_TRUE(loop.finished);
    EXPECT_EQ(loop.forward_fit_steps, 0);
    EXPECT_GT(loop.best_iteration, 0) << "the loop learned nothing: the test has no choice";
    return 0;
  };
  LearningState from_nothing;
  ASSERT_TRUE(run_learning(d.scene, d.observed, options, from_nothing, callbacks));
  EXPECT_EQ(asked, 1);

  LearningOptions no_loop = options;
  no_loop.max_iterations = 0;
  LearningState forward_fit_alone;
  ASSERT_TRUE(run_learning(d.scene, d.observed, no_loop, forward_fit_alone));
  EXPECT_EQ(first_trial_rms(from_nothing), first_trial_rms(forward_fit_alone));
  EXPECT_NE(first_trial_rms(from_nothing), first_trial_rms(from_best));
}

TEST(LearningLoop, TruthEqualToNominalLearnsAlmostNothing) {
  auto scene = bar_scene(bar(material::ElasticModelType::Corotated, 1e6), false);
  scene.frames = 60;
  const auto observed = observe_surface(scene);
  LearningOptions options = small_options();
  options.max_iterations = 1;
  LearningState state;
  ASSERT_TRUE(run_learning(scene, observed, options, state));
  ASSERT_EQ(state.history.size(), 2u);
  const SpaceTimeStages* first = stages_of(state.history.front());
  ASSERT_TRUE(first);
  // The constrained simulation reproduces the data and the physics holds: the control forces
  // are at the solver's residual level, ~1e-6 of the weight of a vertex (mg ≈ 0.05 N here).
  EXPECT_LT(first->control_force_rms, 1e-5);
  EXPECT_LT(first->correction_target, 1e-5);
  ASSERT_TRUE(state.correction);
  // The fitted correction is negligible against the nominal stress at 5 % strain (~5e4 Pa).
  for (const Vec3& s : { Vec3(1.05, 1.0, 0.98), Vec3(0.97, 1.0, 1.0), Vec3(1, 1, 1) })
    EXPECT_LT(state.correction->correction(s, Vec3::Zero()).norm(), 50.0) << s.transpose();
  // Its forward simulation is as good as the nominal's (which is exact).
  // The last step is the loop's last forward check (no trajectory stages).
  const auto* last = std::get_if<LoopRecord>(&state.history.back());
  ASSERT_TRUE(last);
  EXPECT_TRUE(std::holds_alternative<LoopEnd>(last->next));
  EXPECT_LT(last->forward.error().max, 1e-5);
}

/// RMS error of `scene` with `correction` (null = nominal) against `observed`.
double rms_error(const sim::Scene& scene, const observe::Observation& observed,
    std::shared_ptr<const material::RbfCorrection> correction) {
  const auto run = sim::simulate_positions(sim::with_correction(scene, std::move(correction)));
  EXPECT_TRUE(run.completed) << run.message;
  return run.completed ? observation_error(run.positions, observed).rms : 1e300;
}

TEST(LearningLoop, LearnsOneCorrectionFromTwoMotionsOnDifferentMeshes) {
  // A training set: the droop of the 240-tet bar and the swing of a shorter, coarser bar of the
  // same materials (truth neo-Hookean, nominal corotated and too stiff). The one learned
  // correction must fit both motions far better than the nominal; a stage that used one motion's
  // mesh, basis or equations for another, or dropped a motion, fails one of them.
  const auto truth = bar(material::ElasticModelType::NeoHookean, 1e6);
  const auto nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  auto short_bar = [](test::BarOptions o) {
    o.size = Vec3(0.3, 0.1, 0.1);
    o.cells = { 6, 2, 2 };
    o.frames = 60;
    return bar_scene(o, true);
  };
  const std::vector<Motion> motions { { "droop", bar_scene(nominal, false),
                                          observe_surface(bar_scene(truth, false)) },
    { "swing", short_bar(nominal), observe_surface(short_bar(truth)) } };
  LearningState state;
  ASSERT_TRUE(run_learning(motions, small_options(), state));
  ASSERT_TRUE(state.best);
  const ErrorSummary& first = forward_of(state.history.front()).error();
  // Iteration 0's error is over both motions' observations.
  const ErrorSummary droop_nominal
      = observation_error(sim::simulate_positions(motions[0].scene).positions, motions[0].observed);
  const ErrorSummary swing_nominal
      = observation_error(sim::simulate_positions(motions[1].scene).positions, motions[1].observed);
  EXPECT_EQ(first.samples, droop_nominal.samples + swing_nominal.samples);
  EXPECT_EQ(first.max, std::max(droop_nominal.max, swing_nominal.max));
  for (size_t i = 0; i < motions.size(); ++i) {
    const double before = rms_error(motions[i].scene, motions[i].observed, nullptr);
    const double after = rms_error(motions[i].scene, motions[i].observed, state.best);
    std::printf("[ measured ] %s: RMS error nominal %.4g m, learned %.4g m (%.1f× lower)\n",
        motions[i].name.c_str(), before, after, before / after);
    EXPECT_LT(after, before / 20) << motions[i].name; // measured ≥ 100× lower
  }
}

TEST(LearningLoop, OneMotionThroughTheSpanIsTheSingleSceneRun) {
  auto scene = bar_scene(bar(material::ElasticModelType::Corotated, 1.75e6), false);
  scene.frames = 40;
  auto truth = bar_scene(bar(material::ElasticModelType::NeoHookean, 1e6), false);
  truth.frames = 40;
  const observe::Observation observed = observe_surface(truth);
  LearningOptions options = small_options();
  options.max_iterations = 2;
  options.forward_fit.max_iterations = 1;
  LearningState single, spanned;
  ASSERT_TRUE(run_learning(scene, observed, options, single));
  const Motion motion { "bar", scene, observed };
  ASSERT_TRUE(run_learning(std::span(&motion, 1), options, spanned));
  ASSERT_TRUE(single.best && spanned.best);
  test::expect_same_steps(single.history, spanned.history);
  EXPECT_EQ(single.best->parameters().weights, spanned.best->parameters().weights);
  EXPECT_EQ(single.best->parameters().centres, spanned.best->parameters().centres);
  EXPECT_EQ(single.best_error, spanned.best_error);
}

TEST(LearningLoop, TwoCopiesOfAMotionMeasureAsOneAndStillLearn) {
  // The same motion twice: its errors are counted twice, so iteration 0 (the nominal, before any
  // fit) measures what one copy does (up to the rounding of the weighted RMS), with twice the
  // samples. The corrections differ: the reconstruction's equations are doubled against one
  // Tikhonov term, and k-means++ seeds differently from twice the samples (measured best RMS
  // 2.9e-5 m against one copy's 1.8e-5 m, from 4.9e-3 m); the learned one must still beat the
  // nominal by far (a dropped or misaligned copy's equations would not).
  auto scene = bar_scene(bar(material::ElasticModelType::Corotated, 1.75e6), false);
  scene.frames = 40;
  auto truth = bar_scene(bar(material::ElasticModelType::NeoHookean, 1e6), false);
  truth.frames = 40;
  const Motion motion { "bar", scene, observe_surface(truth) };
  const std::vector<Motion> twice { motion, motion };
  LearningOptions options = small_options();
  options.max_iterations = 2;
  LearningState one, two;
  ASSERT_TRUE(run_learning(std::span(&motion, 1), options, one));
  ASSERT_TRUE(run_learning(twice, options, two));
  const ErrorSummary &a = forward_of(one.history.front()).error(),
                     &b = forward_of(two.history.front()).error();
  EXPECT_EQ(b.samples, 2 * a.samples);
  EXPECT_EQ(b.max, a.max);
  EXPECT_DOUBLE_EQ(b.rms, a.rms);
  EXPECT_DOUBLE_EQ(b.mean, a.mean);
  ASSERT_TRUE(stages_of(one.history.front()) && stages_of(two.history.front()));
  EXPECT_EQ(stages_of(two.history.front())->modes, 2 * stages_of(one.history.front())->modes);
  EXPECT_DOUBLE_EQ(test::control_rms(two.history.front()), test::control_rms(one.history.front()));
  ASSERT_TRUE(two.best);
  std::printf("[ measured ] best RMS error: one copy %.3g m, two copies %.3g m, nominal %.3g m\n",
      one.best_error, two.best_error, a.rms);
  EXPECT_LT(two.best_error, 0.05 * a.rms);
}

TEST(LearningLoop, ComparesWithTheRecordedPositionsAndFollowsTheSmoothedOnes) {
  // Truth = nominal, observed exactly, with a "smoothed" copy that drifts sideways (0 → 1 mm
  // along y over the motion). The stages that differentiate positions follow the smoothed copy:
  // the constrained simulation needs control forces to hold the drift (where it follows the exact
  // data they stay below 1e-5 N, TruthEqualToNominalLearnsAlmostNothing). Every comparison of a
  // simulation with the data uses the recorded positions: the nominal's forward error and the
  // forward fit's stay at the solver's rounding, not at the drift's 0.6 mm RMS.
  auto scene = bar_scene(bar(material::ElasticModelType::Corotated, 1e6), false);
  scene.frames = 40;
  Motion motion { "bar", scene, observe_surface(scene) };
  auto drifted = std::make_shared<observe::Observation>(motion.observed);
  for (int t = 0; t < drifted->num_frames(); ++t)
    drifted->positions[static_cast<size_t>(t)].col(1).array()
        += 1e-3 * t / (drifted->num_frames() - 1);
  motion.smoothed = drifted;
  LearningOptions options = small_options();
  options.max_iterations = 1;
  options.forward_fit.max_iterations = 1;
  LearningState state;
  ASSERT_TRUE(run_learning(std::span(&motion, 1), options, state));
  const double control = test::control_rms(state.history.front());
  std::printf("[ measured ] control force rms %.3g N; nominal's forward error max %.3g m\n",
      control, forward_of(state.history.front()).error().max);
  EXPECT_GT(control, 1e-4);
  EXPECT_LT(forward_of(state.history.front()).error().max, 1e-5);
  const ForwardFitRecord* fit = forward_fit_of(state.history.back());
  ASSERT_TRUE(fit);
  ASSERT_TRUE(fit->forward.completed()) << fit->forward.message();
  EXPECT_LT(fit->forward.error().max, 1e-5);
}

TEST(LearningLoop, RefusesAnEmptyTrainingSetAndNamesTheMotion) {
  LearningState state;
  EXPECT_THROW(run_learning(std::span<const Motion>(), small_options(), state), InputError);
  auto scene = bar_scene(bar(material::ElasticModelType::Corotated, 1e6), false);
  scene.frames = 10;
  const auto observed = observe_surface(scene);
  auto longer = scene;
  longer.frames = 12;
  const std::vector<Motion> motions { { "a", scene, observed }, { "b", longer, observed } };
  try {
    run_learning(motions, small_options(), state);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.where()).rfind("motions[1].observations", 0), 0u) << e.what();
  }
}

} // namespace
TEST(LearningLoop, TheSmoothExpansionLearnsAndItsCorrectionsCarryIt) {
  // `learn --continuation smooth_expansion`: every correction the loop writes is continued by the
  // exact smooth expansion (with the nominal's rest stiffness for its floor), and the learned
  // material simulates the unseen swing, which goes beyond the droop's stretches, well below the
  // nominal's error (the 5× of the tests above).
  const auto truth = bar(material::ElasticModelType::NeoHookean, 1e6);
  const auto nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  const auto observed = observe_surface(bar_scene(truth, false));
  LearningOptions options = small_options();
  options.rbf.energy_kernels = true;
  options.rbf.continuation = material::Continuation::smooth_expansion;
  LearningState state;
  ASSERT_TRUE(run_learning(bar_scene(nominal, false), observed, options, state));
  const auto* rbf = dynamic_cast<const material::RbfCorrection*>(state.best.get());
  ASSERT_NE(rbf, nullptr);
  const material::TrustedStretches& t = rbf->parameters().trusted;
  EXPECT_EQ(t.continuation, material::Continuation::smooth_expansion);
  EXPECT_TRUE(t.bounded());
  EXPECT_EQ(t.nominal_stiffness,
      bar_scene(nominal, false).material.elastic->principal_stress_derivative(Vec3::Ones()));
  const double nominal_error = swing_error(bar_scene(truth, true), bar_scene(nominal, true));
  const double learned_error = swing_error(
      bar_scene(truth, true), sim::with_correction(bar_scene(nominal, true), state.best));
  std::printf("[ measured ] smooth expansion: err_L nominal %.4f %%, learned %.4f %%\n",
      nominal_error, learned_error);
  EXPECT_LT(learned_error, nominal_error / 5);
}

} // namespace elastolearn::learn
