// Lost markers (issue 20): observation entries marked lost change nothing in any stage's result
// when their stored positions are garbage (NaN, huge, or any other value), so every consumer
// ignores them; the errors count only seen entries; and learning from a capture with a fifth of
// its marker-frames lost in bursts still beats the nominal model on a different motion.
#include <elastolearn/learn/forward_fit.hpp>
#include <elastolearn/learn/learning_loop.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/learn/space_time.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/observe/marker_dropout.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <support/bar_scene.hpp>
#include <support/learning_history.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace elastolearn::learn {
namespace {

using test::learning_bar;

/// A third of the surface of `truth`'s motion with a fifth of the marker-frames lost in bursts
/// (NaN where lost).
observe::Observation observe_with_dropout(const sim::Scene& truth) {
  const auto run = sim::simulate_positions(truth);
  EXPECT_TRUE(run.completed);
  std::vector<Positions> frames;
  for (const auto& x : run.positions)
    frames.emplace_back(unflatten(x));
  observe::Observation o = observe::observe_vertices(
      frames, truth.dt, observe::select_visible_vertices(truth.mesh, 0.3, 1), 0.0, 7);
  observe::drop_markers(o, 0.2, 5, 3);
  EXPECT_TRUE(o.has_lost_entries());
  return o;
}

/// `o` with every lost entry's position replaced by `value`.
observe::Observation with_garbage(observe::Observation o, double value) {
  for (int t = 0; t < o.num_frames(); ++t)
    for (int j = 0; j < o.num_observed(); ++j)
      if (!o.is_valid(t, j))
        o.positions[static_cast<size_t>(t)].row(j).setConstant(value);
  return o;
}

struct DropoutCase {
  sim::Scene nominal = learning_bar(material::ElasticModelType::Corotated, 1.75e6, false);
  sim::Scene truth = learning_bar(material::ElasticModelType::NeoHookean, 1e6, false);
  observe::Observation observed = observe_with_dropout(truth); // NaN where lost
  observe::Observation huge = with_garbage(observed, 1e300);
  observe::Observation other = with_garbage(observed, -0.37);
};

const DropoutCase& the_case() {
  static const DropoutCase c;
  return c;
}

TEST(LostMarkers, ObservationErrorCountsOnlySeenEntries) {
  const DropoutCase& c = the_case();
  const auto run = sim::simulate_positions(c.nominal);
  ASSERT_TRUE(run.completed);
  const ErrorSummary e = observation_error(run.positions, c.huge);
  EXPECT_EQ(e.samples, c.observed.num_valid());
  double sum = 0, max = 0;
  for (int t = 0; t < c.observed.num_frames(); ++t)
    for (int j = 0; j < c.observed.num_observed(); ++j)
      if (c.observed.is_valid(t, j)) {
        const double d = (run.positions[t].segment<3>(3 * c.observed.vertex_ids[j])
            - c.observed.positions[t].row(j).transpose())
                             .norm();
        sum += d * d;
        max = std::max(max, d);
      }
  EXPECT_NEAR(e.rms, std::sqrt(sum / double(e.samples)), 1e-12 * e.rms);
  EXPECT_EQ(e.max, max);
  EXPECT_EQ(observation_error(run.positions, c.observed).rms, e.rms);
}

TEST(LostMarkers, ParameterFitIgnoresLostEntries) {
  const DropoutCase& c = the_case();
  ParameterFitOptions options;
  options.max_iterations = 3;
  material::ElasticModelType type {};
  const NominalParameters start = nominal_parameters_of(c.nominal.material, type);
  const auto a = fit_parameters(c.nominal, type, start, c.observed, options);
  const auto b = fit_parameters(c.nominal, type, start, c.huge, options);
  const auto d = fit_parameters(c.nominal, type, start, c.other, options);
  for (const auto* r : { &b, &d }) {
    EXPECT_EQ(r->fitted.young, a.fitted.young);
    EXPECT_EQ(r->fitted.poisson, a.fitted.poisson);
    EXPECT_EQ(r->fitted.alpha1, a.fitted.alpha1);
    EXPECT_EQ(r->final_rms, a.final_rms);
    EXPECT_EQ(r->final_max, a.final_max);
  }
  // The same fit from the complete data (the truth at every entry): losing a fifth of the
  // entries moves the fitted E by 2.6 % (measured) after the same three iterations.
  observe::Observation complete = c.observed;
  complete.valid.resize(0, 0);
  const auto truth_run = sim::simulate_positions(c.truth);
  for (int t = 0; t < complete.num_frames(); ++t)
    for (int j = 0; j < complete.num_observed(); ++j)
      complete.positions[t].row(j)
          = truth_run.positions[t].segment<3>(3 * complete.vertex_ids[j]).transpose();
  const auto f = fit_parameters(c.nominal, type, start, complete, options);
  EXPECT_NEAR(a.fitted.young / f.fitted.young, 1, 0.05);
  EXPECT_NEAR(a.final_rms / f.final_rms, 1, 0.1);
  EXPECT_LT(a.final_rms, 0.8 * a.initial_rms) << "the fit learns from the seen entries";
}

TEST(LostMarkers, SpaceTimeAndForwardFitIgnoreLostEntries) {
  const DropoutCase& c = the_case();
  const auto run = sim::simulate_positions(c.nominal);
  ASSERT_TRUE(run.completed);
  // A basis of a few displacement snapshots (any basis with zero rows at the clamp will do).
  MatX basis(run.positions.front().size(), 3);
  for (int i = 0; i < 3; ++i)
    basis.col(i) = run.positions[static_cast<size_t>(20 * (i + 1))] - run.positions.front();
  basis = basis.householderQr().householderQ() * MatX::Identity(basis.rows(), 3);
  for (int v : c.nominal.prescribed_vertices())
    basis.middleRows(3 * v, 3).setZero();
  const auto evaluate = [&](const observe::Observation& o) {
    TrajectoryPhysics physics(c.nominal);
    SpaceTimeProblem problem(physics, basis, c.nominal.frames, run.initial_velocity, o, 1.0);
    BlockBandedMatrix normal(c.nominal.frames + 1, 3);
    VecX gradient;
    problem.assemble(run.positions, normal, gradient);
    return std::tuple { problem.evaluate(run.positions), MatX(normal.block(30, 30)), gradient };
  };
  const auto [value, block, gradient] = evaluate(c.observed);
  EXPECT_GT(value.position_squares, 0);
  EXPECT_TRUE(gradient.allFinite());
  for (const auto* o : { &c.huge, &c.other }) {
    const auto [v, b, g] = evaluate(*o);
    EXPECT_EQ(v.position_squares, value.position_squares);
    EXPECT_EQ(v.physics, value.physics);
    EXPECT_EQ(b, block);
    EXPECT_EQ(g, gradient);
  }

  const ReconstructionMesh mesh(c.nominal.mesh, c.nominal.material);
  MatX centres(2, 3);
  centres << 1.05, 1.0, 0.98, 0.97, 1.0, 0.99;
  const RbfDesign design(centres, RbfFitOptions {});
  const VecX start = VecX::Zero(design.num_unknowns());
  const auto pass = [&](const observe::Observation& o) {
    return simulate_with_sensitivities(c.nominal, o, mesh, design, start, Sensitivities::projected);
  };
  const ForwardSensitivityPass a = pass(c.observed);
  ASSERT_TRUE(a.completed) << a.message;
  EXPECT_EQ(a.error.samples, c.observed.num_valid());
  EXPECT_TRUE(a.normal.allFinite() && a.gradient.allFinite());
  for (const auto* o : { &c.huge, &c.other }) {
    const ForwardSensitivityPass b = pass(*o);
    EXPECT_EQ(b.squared_error, a.squared_error);
    EXPECT_EQ(b.normal, a.normal);
    EXPECT_EQ(b.gradient, a.gradient);
  }
}

TEST(LostMarkers, LearningLoopResultDoesNotDependOnLostPositions) {
  // The raw loop (no smoothing before it): its constrained simulation follows filled gaps.
  const DropoutCase& c = the_case();
  LearningOptions options;
  options.max_iterations = 2;
  options.centres = 10;
  options.pod.max_modes = 8;
  options.forward_fit.max_iterations = 1;
  const auto learn = [&](const observe::Observation& o) {
    LearningState state;
    EXPECT_TRUE(run_learning(c.nominal, o, options, state));
    return state;
  };
  const LearningState a = learn(c.observed);
  ASSERT_TRUE(a.best) << "the loop learned something";
  EXPECT_LT(a.best_error, test::forward_rms(a.history.front()));
  for (const auto* o : { &c.huge, &c.other }) {
    const LearningState b = learn(*o);
    test::expect_same_steps(b.history, a.history);
    ASSERT_TRUE(b.best);
    EXPECT_EQ(b.best->parameters().weights, a.best->parameters().weights);
  }
}

TEST(LostMarkers, RecipeResultDoesNotDependOnLostPositionsAndBeatsTheNominal) {
  const DropoutCase& c = the_case();
  RecipeOptions options;
  options.parameter_fit.max_iterations = 4;
  options.loop.max_iterations = 2;
  options.loop.centres = 15;
  options.loop.pod.max_modes = 10;
  options.loop.forward_fit.max_iterations = 1;
  options.network.enabled = false; // stage 5 validates through the same code (tested there)
  const auto learn = [&](const observe::Observation& o) {
    const std::vector<Motion> motions { { "droop", c.nominal, o } };
    return learn_material(motions, options);
  };
  const RecipeResult a = learn(c.observed), b = learn(c.huge);
  EXPECT_EQ(b.noise.sigma, a.noise.sigma);
  EXPECT_EQ(b.parameter_fit.fitted.young, a.parameter_fit.fitted.young);
  ASSERT_EQ(b.candidates.size(), a.candidates.size());
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_EQ(b.candidates[i].validation.rms, a.candidates[i].validation.rms) << i;
    EXPECT_EQ(b.candidates[i].validation.samples, a.candidates[i].validation.samples) << i;
  }
  EXPECT_EQ(b.chosen, a.chosen);
  // The result predicts a different motion (a swing) much better than the nominal (measured:
  // err_L 4.45 % nominal, 0.56 % learned with this small budget).
  const sim::Scene swing = learning_bar(material::ElasticModelType::NeoHookean, 1e6, true);
  const auto test_error = [&](const fem::MaterialModel& material) {
    sim::Scene s = swing;
    s.material = material;
    const auto run = sim::simulate_positions(s);
    EXPECT_TRUE(run.completed);
    return as_percent_of(position_error(run.positions, sim::simulate_positions(swing).positions),
        s.mesh.bounding_box_diagonal())
        .max;
  };
  const double nominal = test_error(c.nominal.material);
  const double learned = test_error(a.material(c.nominal.material));
  std::cout << "[ lost markers ] swing err_L nominal " << nominal << " %, learned " << learned
            << " %\n";
  EXPECT_LT(learned, nominal / 3);
}

} // namespace
} // namespace elastolearn::learn
