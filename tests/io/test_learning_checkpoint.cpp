// Checkpoints of the learning loop: an interrupted run resumed from its checkpoint file reaches
// exactly the result of an uninterrupted run (issue 3, "Resume after interruption gives the same
// learned material"), and a checkpoint of other inputs is refused.
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include "io_test_util.hpp"
#include <support/bar_scene.hpp>
#include <support/learning_history.hpp>

#include <gtest/gtest.h>

#include <filesystem>

namespace elastolearn::io {
namespace {

sim::Scene bar(material::ElasticModelType type, double young) {
  return elastolearn::test::bar_scene(
      { .model = type, .young = young, .poisson = 0.43, .alpha1 = 0.01, .dt = 4e-3, .frames = 40 });
}

struct Fixture {
  sim::Scene nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  observe::Observation observed;
  learn::LearningOptions options;
  LearningInputs inputs;
  // Each test its own directory: ctest runs the tests of this file in parallel processes.
  test::ScratchDir scratch;
  std::filesystem::path file = scratch / "checkpoint.json";
  Fixture() {
    const auto run = sim::simulate_positions(bar(material::ElasticModelType::NeoHookean, 1e6));
    std::vector<Positions> frames;
    for (const auto& x : run.positions)
      frames.emplace_back(unflatten(x));
    observed = observe::observe_vertices(
        frames, nominal.dt, observe::select_visible_vertices(nominal.mesh, 0.3, 1), 0, 1);
    options.max_iterations = 2;
    options.centres = 10;
    options.pod.max_modes = 8;
    inputs = { "scene.json", "obs.h5", learning_options_to_json(options) };
  }
};

void expect_same(const material::RbfCorrection& a, const material::RbfCorrection& b) {
  EXPECT_EQ(a.parameters().centres, b.parameters().centres);
  EXPECT_EQ(a.parameters().weights, b.parameters().weights);
  EXPECT_EQ(a.parameters().own_slope, b.parameters().own_slope);
  EXPECT_EQ(a.parameters().other_slope, b.parameters().other_slope);
  EXPECT_EQ(a.parameters().damping_weights, b.parameters().damping_weights);
}

/// a and b are the same function to `relative_tolerance` (of the largest |N|) at stretches
/// around rest, for corrections of different builds (their centres and weights then differ by
/// rounding).
void expect_close_function(
    const material::RbfCorrection& a, const material::RbfCorrection& b, double relative_tolerance) {
  double scale = 0, difference = 0;
  for (const Vec3& s : { Vec3(1.02, 1.0, 0.99), Vec3(1.05, 0.98, 0.97), Vec3(0.97, 1.01, 1.0),
           Vec3(1.1, 1.0, 0.9) }) {
    const Vec3 na = a.correction(s, Vec3::Zero()), nb = b.correction(s, Vec3::Zero());
    scale = std::max(scale, na.cwiseAbs().maxCoeff());
    difference = std::max(difference, (na - nb).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(difference, relative_tolerance * scale);
}

/// Run f's learning whole, and interrupted after checkpoint `stop_after` then resumed from the
/// file: both must reach the same history and the bit-identical correction.
void expect_resume_equals_whole(Fixture& f, int stop_after) {
  f.inputs.options = learning_options_to_json(f.options);
  learn::LearningState whole;
  ASSERT_TRUE(learn::run_learning(f.nominal, f.observed, f.options, whole));
  ASSERT_TRUE(whole.best);
  EXPECT_EQ(whole.forward_fit_steps, f.options.forward_fit.max_iterations);

  learn::LearningState first;
  int saved = 0;
  learn::LearningCallbacks callbacks;
  callbacks.checkpoint = [&](const learn::LearningState& s) {
    write_learning_checkpoint(f.file, f.inputs, { {}, s });
    ++saved;
  };
  callbacks.interrupted = [&] { return saved >= stop_after; };
  EXPECT_FALSE(learn::run_learning(f.nominal, f.observed, f.options, first, callbacks));
  learn::LearningState resumed = read_learning_checkpoint(f.file, f.inputs).loop;
  EXPECT_EQ(resumed.next_iteration, stop_after);
  ASSERT_TRUE(learn::run_learning(f.nominal, f.observed, f.options, resumed));

  EXPECT_EQ(resumed.best_iteration, whole.best_iteration);
  EXPECT_EQ(resumed.best_error, whole.best_error);
  EXPECT_EQ(resumed.forward_fit_steps, whole.forward_fit_steps);
  elastolearn::test::expect_same_steps(resumed.history, whole.history);
  ASSERT_TRUE(resumed.best);
  expect_same(*resumed.best, *whole.best); // bit-identical: every stage is deterministic
  // Every correction a completed step simulated, which the recipe's validation draws from.
  ASSERT_EQ(resumed.tried.size(), whole.tried.size());
  for (const auto& [iteration, correction] : whole.tried) {
    ASSERT_TRUE(resumed.tried.contains(iteration)) << iteration;
    expect_same(*resumed.tried.at(iteration), *correction);
  }
}

TEST(LearningCheckpoint, ResumedRunEqualsUninterruptedRun) {
  Fixture f;
  expect_resume_equals_whole(f, 1); // interrupted after the first iteration
}

TEST(LearningCheckpoint, ResumedForwardFitEqualsUninterruptedRun) {
  // The forward fit after the loop: interrupted after its first step (checkpoint 4 = iterations
  // 0–2 of the loop, then that step), resumed with the saved μ from the best correction.
  Fixture f;
  f.options.forward_fit.max_iterations = 2;
  expect_resume_equals_whole(f, 4);
}

TEST(LearningCheckpoint, RefusesACheckpointOfOtherInputs) {
  Fixture f;
  learn::LearningState state;
  state.next_iteration = 3;
  state.failed_steps_in_a_row = 2;
  state.forward_fit_steps = 1;
  state.forward_fit_damping = 3.3e-3;
  state.forward_fit_converged = true;
  learn::ParameterFitReport fit;
  fit.fitted = { 1.25e6, 0.41, 0.5, 0.02 };
  fit.final_rms = 1.5e-4;
  fit.diverged = 3;
  fit.unheld_loads = 2;
  fit.stop = learn::FitStop::Converged;
  write_learning_checkpoint(f.file, f.inputs, { fit, state });
  const learn::RecipeResume resume = read_learning_checkpoint(f.file, f.inputs);
  const learn::LearningState& read = resume.loop;
  EXPECT_EQ(resume.parameter_fit.fitted.young, 1.25e6);
  EXPECT_EQ(resume.parameter_fit.fitted.alpha1, 0.02);
  EXPECT_EQ(resume.parameter_fit.final_rms, 1.5e-4);
  EXPECT_EQ(resume.parameter_fit.diverged, 3);
  EXPECT_EQ(resume.parameter_fit.unheld_loads, 2);
  EXPECT_EQ(resume.parameter_fit.stop, learn::FitStop::Converged);
  EXPECT_EQ(read.next_iteration, 3);
  EXPECT_EQ(read.failed_steps_in_a_row, 2);
  EXPECT_EQ(read.forward_fit_steps, 1);
  EXPECT_EQ(read.forward_fit_damping, 3.3e-3);
  EXPECT_TRUE(read.forward_fit_converged);
  auto other = f.inputs;
  other.scene = "other.json";
  EXPECT_THROW(read_learning_checkpoint(f.file, other), InputError);
  other = f.inputs;
  other.options["centres"] = 11;
  try {
    read_learning_checkpoint(f.file, other);
    ADD_FAILURE() << "other options accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("options"), std::string::npos) << e.what();
  }
}

/// One record of every kind a run writes.
std::vector<learn::IterationRecord> every_kind_of_step() {
  learn::ErrorSummary e { 2e-3, 5e-4, 7e-4, 12, 34, 5600 };
  learn::SpaceTimeStages t;
  t.modes = 20;
  t.control_force_rms = 1.5e-2;
  t.space_time_initial = 3e-6;
  t.space_time_objective = 1e-6;
  t.space_time_iterations = 3;
  t.centres = 40;
  t.correction_misfit = 0.25;
  t.correction_target = 0.75;
  t.stability = -0.125;
  t.step_kept = 0.5;
  t.stability_cuts = 12;
  t.seconds_pod = 0.5;
  t.seconds_constrained = 1.5;
  t.seconds_space_time = 2.5;
  t.seconds_reconstruction = 3.5;
  using learn::ForwardOutcome;
  return { learn::LoopRecord { 0, ForwardOutcome::completed(e, 1.25), t },
    learn::LoopRecord {
        1, ForwardOutcome::diverged("diverged at frame 7", 0.75), learn::DampedUpdate {} },
    learn::LoopRecord {
        2, ForwardOutcome::diverged("diverged at frame 9", 0.5), learn::LoopEnd {} },
    learn::LoopRecord { 3, ForwardOutcome::completed(e, 1), learn::LoopEnd {} },
    learn::ForwardFitRecord { 4, ForwardOutcome::completed(e, 2), true, 40 },
    learn::ForwardFitRecord { 5, ForwardOutcome::completed(e, 2), false, 40 },
    learn::ForwardFitRecord {
        6, ForwardOutcome::unstable("unstable at 3 samples", 0.125), false, 40 },
    learn::ForwardFitRecord {
        7, ForwardOutcome::diverged("diverged at frame 2", 0.25), false, 40 } };
}

/// a and b are the same record, every field.
void expect_same_record(const learn::IterationRecord& a, const learn::IterationRecord& b) {
  ASSERT_EQ(a.index(), b.index());
  const int k = learn::iteration_of(a);
  EXPECT_EQ(k, learn::iteration_of(b));
  const learn::ForwardOutcome &fa = learn::forward_of(a), &fb = learn::forward_of(b);
  EXPECT_EQ(fa.status(), fb.status()) << k;
  EXPECT_EQ(fa.message(), fb.message()) << k;
  EXPECT_EQ(fa.seconds(), fb.seconds()) << k;
  if (fa.completed() && fb.completed()) {
    const learn::ErrorSummary &ea = fa.error(), &eb = fb.error();
    EXPECT_EQ(ea.max, eb.max);
    EXPECT_EQ(ea.mean, eb.mean);
    EXPECT_EQ(ea.rms, eb.rms);
    EXPECT_EQ(ea.worst_frame, eb.worst_frame);
    EXPECT_EQ(ea.worst_vertex, eb.worst_vertex);
    EXPECT_EQ(ea.samples, eb.samples);
  }
  if (const auto* sa = std::get_if<learn::ForwardFitRecord>(&a)) {
    const auto& sb = std::get<learn::ForwardFitRecord>(b);
    EXPECT_EQ(sa->accepted, sb.accepted) << k;
    EXPECT_EQ(sa->centres, sb.centres) << k;
    return;
  }
  const auto &la = std::get<learn::LoopRecord>(a), &lb = std::get<learn::LoopRecord>(b);
  ASSERT_EQ(la.next.index(), lb.next.index()) << k;
  if (const auto* ta = la.stages()) {
    const auto* tb = lb.stages();
    EXPECT_EQ(ta->modes, tb->modes);
    EXPECT_EQ(ta->control_force_rms, tb->control_force_rms);
    EXPECT_EQ(ta->space_time_initial, tb->space_time_initial);
    EXPECT_EQ(ta->space_time_objective, tb->space_time_objective);
    EXPECT_EQ(ta->space_time_iterations, tb->space_time_iterations);
    EXPECT_EQ(ta->centres, tb->centres);
    EXPECT_EQ(ta->correction_misfit, tb->correction_misfit);
    EXPECT_EQ(ta->correction_target, tb->correction_target);
    EXPECT_EQ(ta->stability, tb->stability);
    EXPECT_EQ(ta->step_kept, tb->step_kept);
    EXPECT_EQ(ta->stability_cuts, tb->stability_cuts);
    EXPECT_EQ(ta->seconds_pod, tb->seconds_pod);
    EXPECT_EQ(ta->seconds_constrained, tb->seconds_constrained);
    EXPECT_EQ(ta->seconds_space_time, tb->seconds_space_time);
    EXPECT_EQ(ta->seconds_reconstruction, tb->seconds_reconstruction);
  }
}

TEST(LearningCheckpoint, EveryKindOfStepSurvivesTheFile) {
  Fixture f;
  learn::LearningState state;
  state.history = every_kind_of_step();
  write_learning_checkpoint(f.file, f.inputs, { {}, state });
  EXPECT_EQ(read_json_file(f.file).at("format"), "elastolearn-learning-checkpoint/3");
  const learn::LearningState read = read_learning_checkpoint(f.file, f.inputs).loop;
  ASSERT_EQ(read.history.size(), state.history.size());
  for (size_t i = 0; i < state.history.size(); ++i)
    expect_same_record(read.history[i], state.history[i]);
  // Only what a step measured is written: no stages without them, no error without a completed
  // simulation.
  const nlohmann::json history = read_json_file(f.file).at("state").at("history");
  EXPECT_EQ(history[1].at("next"), "damped_update");
  EXPECT_FALSE(history[1].contains("stages"));
  EXPECT_FALSE(history[1].at("forward").contains("error"));
  EXPECT_EQ(history[1].at("forward").at("message"), "diverged at frame 7");
  EXPECT_EQ(history[3].at("next"), "end");
  EXPECT_EQ(history[6].at("forward").at("status"), "unstable");
}

TEST(LearningCheckpoint, ReadsTheFlatRecordsOfVersion2) {
  // A version-2 record per kind of step, as version 2 wrote them (flags, zeros where nothing
  // was measured): each must read as the record of its kind.
  Fixture f;
  auto flat = [](int iteration, bool completed, bool unstable, bool damped, bool fit, bool accepted,
                  int modes, int centres) {
    return nlohmann::json { { "iteration", iteration },
      { "forward_error",
          { { "max", completed ? 2e-3 : 0.0 }, { "mean", completed ? 5e-4 : 0.0 },
              { "rms", completed ? 7e-4 : 0.0 }, { "worst_frame", completed ? 12 : -1 },
              { "worst_vertex", completed ? 34 : -1 }, { "samples", completed ? 5600 : 0 } } },
      { "forward_completed", completed }, { "forward_unstable", unstable },
      { "damped_update", damped }, { "forward_fit", fit }, { "forward_fit_accepted", accepted },
      { "control_force_rms", modes > 0 ? 1.5e-2 : 0.0 },
      { "space_time_initial", modes > 0 ? 3e-6 : 0.0 },
      { "space_time_objective", modes > 0 ? 1e-6 : 0.0 },
      { "space_time_iterations", modes > 0 ? 3 : 0 }, { "modes", modes }, { "centres", centres },
      { "correction_misfit", modes > 0 ? 0.25 : 0.0 },
      { "correction_target", modes > 0 ? 0.75 : 0.0 }, { "stability", modes > 0 ? -0.125 : 0.0 },
      { "step_kept", modes > 0 ? 0.5 : 1.0 },
      { "seconds",
          { { "forward", 1.0 }, { "pod", modes > 0 ? 0.5 : 0.0 },
              { "constrained", modes > 0 ? 1.5 : 0.0 }, { "space_time", modes > 0 ? 2.5 : 0.0 },
              { "reconstruction", modes > 0 ? 3.5 : 0.0 }, { "total", 9.0 } } } };
  };
  nlohmann::json j
      = read_json_file(std::string(ELASTOLEARN_TEST_DATA_DIR) + "/io/learning_checkpoint_v2.json");
  j["inputs"]["options"] = f.inputs.options;
  j["state"]["history"] = { flat(0, true, false, false, false, false, 20, 40),
    flat(1, false, false, true, false, false, 0, 0),
    flat(2, false, false, false, false, false, 0, 0),
    flat(3, true, false, false, false, false, 0, 0), flat(4, true, false, false, true, true, 0, 40),
    flat(5, true, false, false, true, false, 0, 40),
    flat(6, false, true, false, true, false, 0, 40),
    flat(7, false, false, false, true, false, 0, 40) };
  const std::vector<learn::IterationRecord> expected = every_kind_of_step();
  for (size_t i = 0; i < expected.size(); ++i)
    j["state"]["history"][i]["forward_message"] = learn::forward_of(expected[i]).message();
  write_json_file(f.file, j);
  const learn::LearningState read = read_learning_checkpoint(f.file, f.inputs).loop;
  ASSERT_EQ(read.history.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    // Version 2 kept one time per stage and the forward time; the test writes 1 s for every
    // forward simulation.
    const learn::IterationRecord& r = read.history[i];
    EXPECT_EQ(learn::forward_of(r).seconds(), 1.0);
    EXPECT_EQ(r.index(), expected[i].index()) << i;
    EXPECT_EQ(learn::forward_of(r).status(), learn::forward_of(expected[i]).status()) << i;
    EXPECT_EQ(learn::forward_of(r).message(), learn::forward_of(expected[i]).message()) << i;
    if (const auto* loop = std::get_if<learn::LoopRecord>(&r))
      EXPECT_EQ(loop->next.index(), std::get<learn::LoopRecord>(expected[i]).next.index()) << i;
    else
      EXPECT_EQ(learn::forward_fit_of(r)->accepted, learn::forward_fit_of(expected[i])->accepted)
          << i;
  }
  const learn::SpaceTimeStages* t = learn::stages_of(read.history[0]);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->modes, 20);
  EXPECT_EQ(t->step_kept, 0.5);
  EXPECT_EQ(t->stability_cuts, 0); // older checkpoints have none
  EXPECT_EQ(t->seconds_reconstruction, 3.5);
  EXPECT_EQ(learn::forward_of(read.history[0]).error().worst_vertex, 34);
}

TEST(LearningCheckpoint, ResumesACheckpointWrittenInVersion2) {
  // tests/data/io/learning_checkpoint_v2.json: this fixture's run (forward fit of 2 steps)
  // interrupted after checkpoint 4 (loop iterations 0–2, the first forward-fit step), written by
  // the version-2 code. Resumed now, it reaches the uninterrupted run's history and correction.
  // Its first steps were computed by that older build, whose element kernel rounded differently
  // (the damping stress summed in another order): measured, the steps agree to ~2e-11 and the
  // corrections' stresses to rounding amplified by the k-means and the fit, not bit for bit.
  Fixture f;
  f.options.forward_fit.max_iterations = 2;
  f.inputs.options = learning_options_to_json(f.options);
  learn::LearningState resumed = read_learning_checkpoint(
      std::string(ELASTOLEARN_TEST_DATA_DIR) + "/io/learning_checkpoint_v2.json", f.inputs)
                                     .loop;
  ASSERT_EQ(resumed.history.size(), 4u);
  EXPECT_TRUE(learn::stages_of(resumed.history[0]) && learn::stages_of(resumed.history[1]));
  const auto* check = std::get_if<learn::LoopRecord>(&resumed.history[2]);
  ASSERT_TRUE(check);
  EXPECT_TRUE(std::holds_alternative<learn::LoopEnd>(check->next)) << "the last forward check";
  ASSERT_TRUE(learn::forward_fit_of(resumed.history[3]));
  EXPECT_EQ(resumed.next_iteration, 4);
  ASSERT_TRUE(learn::run_learning(f.nominal, f.observed, f.options, resumed));
  learn::LearningState whole;
  ASSERT_TRUE(learn::run_learning(f.nominal, f.observed, f.options, whole));
  elastolearn::test::expect_same_steps(resumed.history, whole.history, 1e-9);
  EXPECT_EQ(resumed.best_iteration, whole.best_iteration);
  EXPECT_NEAR(resumed.best_error, whole.best_error, 1e-9 * whole.best_error);
  ASSERT_TRUE(resumed.best && whole.best);
  expect_close_function(*resumed.best, *whole.best, 1e-6);
}

TEST(LearningCheckpoint, DefaultPathAndMissingCheckpoint) {
  EXPECT_EQ(learning_checkpoint_path("out/learned.json", ""), "out/learned.json.checkpoint.json");
  EXPECT_EQ(learning_checkpoint_path("out/learned.json", "run.json"), "run.json");
  Fixture f;
  std::filesystem::remove(f.file);
  try {
    resume_learning_checkpoint(f.file, f.inputs, "--resume");
    ADD_FAILURE() << "a missing checkpoint was resumed";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
        f.file.string() + ": no checkpoint to resume from (run without --resume first)");
  }
  write_learning_checkpoint(f.file, f.inputs, { {}, {} });
  EXPECT_EQ(resume_learning_checkpoint(f.file, f.inputs, "--resume").loop.next_iteration, 0);
}

} // namespace
} // namespace elastolearn::io
