// Checkpoints of the learning loop: an interrupted run resumed from its checkpoint file reaches
// exactly the result of an uninterrupted run (issue 3, "Resume after interruption gives the same
// learned material"), and a checkpoint of other inputs is refused.
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/learning_checkpoint.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <support/bar_scene.hpp>

#include <gtest/gtest.h>

#include <filesystem>

namespace elastolearn::io {
namespace {

sim::Scene bar(material::ElasticModelType type, double young) {
  return test::bar_scene(
      { .model = type, .young = young, .poisson = 0.43, .alpha1 = 0.01, .dt = 4e-3, .frames = 40 });
}

struct Fixture {
  sim::Scene nominal = bar(material::ElasticModelType::Corotated, 1.75e6);
  observe::Observation observed;
  learn::LearningOptions options;
  LearningInputs inputs;
  std::filesystem::path file
      = std::filesystem::temp_directory_path() / "elastolearn_test_checkpoint.json";
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
  ~Fixture() { std::filesystem::remove(file); }
};

void expect_same(const material::RbfCorrection& a, const material::RbfCorrection& b) {
  EXPECT_EQ(a.parameters().centres, b.parameters().centres);
  EXPECT_EQ(a.parameters().weights, b.parameters().weights);
  EXPECT_EQ(a.parameters().own_slope, b.parameters().own_slope);
  EXPECT_EQ(a.parameters().other_slope, b.parameters().other_slope);
  EXPECT_EQ(a.parameters().damping_weights, b.parameters().damping_weights);
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
  ASSERT_EQ(resumed.history.size(), whole.history.size());
  for (size_t i = 0; i < whole.history.size(); ++i)
    EXPECT_EQ(resumed.history[i].forward_error.rms, whole.history[i].forward_error.rms)
        << "iteration " << i;
  ASSERT_TRUE(resumed.best);
  expect_same(*resumed.best, *whole.best); // bit-identical: every stage is deterministic
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
  state.divergences_in_a_row = 2;
  state.forward_fit_steps = 1;
  state.forward_fit_damping = 3.3e-3;
  learn::ParameterFitReport fit;
  fit.fitted = { 1.25e6, 0.41, 0.5, 0.02 };
  fit.final_rms = 1.5e-4;
  fit.stop = learn::FitStop::Converged;
  write_learning_checkpoint(f.file, f.inputs, { fit, state });
  const learn::RecipeResume resume = read_learning_checkpoint(f.file, f.inputs);
  const learn::LearningState& read = resume.loop;
  EXPECT_EQ(resume.parameter_fit.fitted.young, 1.25e6);
  EXPECT_EQ(resume.parameter_fit.fitted.alpha1, 0.02);
  EXPECT_EQ(resume.parameter_fit.final_rms, 1.5e-4);
  EXPECT_EQ(resume.parameter_fit.stop, learn::FitStop::Converged);
  EXPECT_EQ(read.next_iteration, 3);
  EXPECT_EQ(read.divergences_in_a_row, 2);
  EXPECT_EQ(read.forward_fit_steps, 1);
  EXPECT_EQ(read.forward_fit_damping, 3.3e-3);
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
