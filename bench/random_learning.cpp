// The random cases of `bench_learning --random N --seed S` (issue 19): per drawn case
// (random_cases.hpp), simulate the truth, learn with the one recipe (options.recipe: its defaults
// unless an expert flag changed them), and compare nominal / fitted / learned on the test motion;
// then the table and issue 19's targets.
#include "random_learning.hpp"

#include "learning_bench_support.hpp"
#include "random_cases.hpp"

#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/observe/visible_vertices.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace bench_learning {

namespace {

struct RandomRow {
  int index = 0;
  std::string shape, truth;
  int tets = 0, observed = 0, attempts = 0;
  bool in_family = false;
  double visible = 1, noise = 0;
  double train_deformation = 0, test_deformation = 0; ///< % of the diagonal
  double err_nominal = -1, err_fit = -1, err_learned = -1; ///< test err_L [%] (−1: diverged)
  double learn_seconds = 0, fit_seconds = 0;
  /// The fitted nominal's training RMS error over the noise's own (√3 σ for a 3-D position;
  /// +∞ without noise). Near 1 the four parameters already explain the training data to the
  /// noise: nothing in it tells a correction from chance, whatever the learner.
  double fit_over_noise = 0;
  int fit_diverged = 0, loop_diverged = 0, validation_diverged = 0; ///< in learning
  /// Parameter-fit simulations whose initial static solve failed (ParameterFitReport::
  /// unheld_loads): parameters the recorded first frame rules out, not in fit_diverged.
  int fit_unheld_loads = 0;
  int test_diverged = 0; ///< of the fitted and learned test simulations
  std::string chosen;
  int learning_divergences() const { return fit_diverged + loop_diverged + validation_diverged; }
};

/// The truth's motions must complete and keep every element far from inversion (sorted
/// stretches within [0.5, 2]), and the training motion must tell the nominal from the truth
/// (their RMS vertex distance over the training ≥ kInformative); otherwise the motions are
/// redrawn, at most kMotionAttempts times (× 0.7 in amplitude after a failure of the truth).
constexpr int kMotionAttempts = 6;
constexpr double kInformative = 0.25; ///< [% of the rest bounding-box diagonal]

/// A drawn object none of whose motions makes a case (the truth cannot follow them, or they cannot
/// tell it from the nominal): the benchmark skips it, it is no learning failure.
struct Undrawable : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Print case `index` of `seed`; unless options.draw_only, simulate its truth, learn with the
/// recipe (options.recipe), and measure nominal / fitted / learned on the test motion (with
/// options.test_candidates, every validated candidate too).
RandomRow run_random_case(std::uint64_t seed, int index, const RandomRunOptions& options) {
  const bool run = !options.draw_only;
  RandomRow row;
  row.index = index;
  std::printf("\n== random case %d of seed %llu (alone: bench_learning --seed %llu --random-case "
              "%d)\n",
      index, static_cast<unsigned long long>(seed), static_cast<unsigned long long>(seed), index);
  std::fflush(stdout);
  auto t0 = Clock::now();
  RandomObject o = draw_random_object(seed, index, options.data);
  const double drawn_noise = o.noise_percent;
  if (options.noise_percent >= 0)
    o.noise_percent = options.noise_percent; // after the draw: every other choice is unchanged
  row.shape = o.shape_label;
  row.truth = o.truth_label;
  row.tets = o.mesh.num_tets();
  row.in_family = o.truth_in_family;
  row.visible = o.visible_fraction;
  row.noise = o.noise_percent;
  std::printf("   shape: %s\n   truth: %s%s\n   nominal: %s\n   %s\n   (drawn in %.1f s)\n",
      o.shape_label.c_str(), o.truth_label.c_str(),
      o.truth_in_family ? "" : " (not in the nominal's family)", o.nominal_label.c_str(),
      o.setup_label.c_str(), seconds_since(t0));
  if (options.noise_percent >= 0)
    std::printf(
        "   --noise: observation noise σ %.2f %% of the diagonal instead of the drawn %.1f %%\n",
        o.noise_percent, drawn_noise);
  std::fflush(stdout);

  RandomMotions motions;
  std::vector<VecX> truth_train, truth_test;
  double scale = 1;
  for (int attempt = 0;; ++attempt) {
    if (attempt == kMotionAttempts)
      throw Undrawable("no drawn motion passed (" + std::to_string(kMotionAttempts)
          + " attempts): the truth cannot follow them or they cannot tell it from the nominal");
    motions = draw_random_motions(o, attempt, scale);
    std::printf("   motions (attempt %d): train: %s\n                        test: %s\n", attempt,
        motions.train_label.c_str(), motions.test_label.c_str());
    std::fflush(stdout);
    if (!run)
      return row;
    row.attempts = attempt + 1;
    std::string problem;
    t0 = Clock::now();
    for (const auto* scene : { &motions.train, &motions.test }) {
      auto result = sim::simulate_positions(with_material(*scene, o.truth));
      const char* which = scene == &motions.train ? "training" : "test";
      if (!result.completed) {
        problem = std::string("the truth's ") + which + " simulation failed: " + result.message;
        scale *= 0.7;
        break;
      }
      const auto range = learn::trajectory_stretch_range(o.mesh, result.positions);
      if (range.min.minCoeff() < 0.5 || range.max.maxCoeff() > 2) {
        problem = std::string("the truth's ") + which
            + " motion nearly inverts elements: " + learn::describe(range);
        scale *= 0.7;
        break;
      }
      (scene == &motions.train ? truth_train : truth_test) = std::move(result.positions);
    }
    if (problem.empty()) {
      // A training motion the nominal already follows (e.g. a keyframed cap that prescribes the
      // shape) holds nothing to learn: no recipe can beat the fit there.
      const auto nominal = sim::simulate_positions(motions.train);
      const double floor = kInformative;
      if (!nominal.completed)
        problem = "the nominal's training simulation failed: " + nominal.message;
      else if (const double rms = learn::as_percent_of(
                   learn::position_error(nominal.positions, truth_train), o.diagonal)
                                      .rms;
               rms < floor)
        problem = "the training motion cannot tell the nominal from the truth (RMS distance "
            + err(rms) + " % < " + err(floor) + " % of the diagonal)";
    }
    if (problem.empty())
      break;
    std::printf("   redrawing the motions: %s\n", problem.c_str());
  }
  row.train_deformation = deformation(truth_train, o.mesh);
  row.test_deformation = deformation(truth_test, o.mesh);
  std::vector<Positions> frames;
  for (const auto& x : truth_train)
    frames.emplace_back(unflatten(x));
  const auto ids = observe::select_visible_vertices(o.mesh, o.visible_fraction, o.observation_seed);
  learn::Motion motion;
  motion.name = "training";
  motion.scene = motions.train;
  motion.observed = observe::observe_vertices(
      frames, o.dt, ids, o.noise_percent / 100 * o.diagonal, o.observation_seed);
  row.observed = motion.observed.num_observed();
  std::printf("   truth simulated in %.1f s: max displacement train %.1f %%, test %.1f %% of the "
              "diagonal; stretches train %s, test %s; observing %d of %zu surface vertices\n",
      seconds_since(t0), row.train_deformation, row.test_deformation,
      learn::describe(learn::trajectory_stretch_range(o.mesh, truth_train)).c_str(),
      learn::describe(learn::trajectory_stretch_range(o.mesh, truth_test)).c_str(), row.observed,
      o.mesh.surface_vertices().size());
  std::fflush(stdout);

  // The one recipe (default options unless an expert flag changed them for every case):
  // nothing here knows the case.
  const learn::RecipeCallbacks callbacks = printing_callbacks(o.diagonal, "   recipe: ");
  t0 = Clock::now();
  const auto result = learn::learn_material(
      std::span<const learn::Motion>(&motion, 1), options.recipe, callbacks);
  row.learn_seconds = seconds_since(t0);
  row.fit_seconds = result.parameter_fit.seconds;
  row.fit_unheld_loads = result.parameter_fit.unheld_loads;
  row.fit_diverged = result.parameter_fit.diverged - row.fit_unheld_loads;
  const double noise_rms = std::sqrt(3.0) * o.noise_percent / 100 * o.diagonal;
  row.fit_over_noise = noise_rms > 0 ? result.parameter_fit.final_rms / noise_rms
                                     : std::numeric_limits<double>::infinity();
  for (const auto& r : result.loop.history)
    row.loop_diverged += diverged(r) ? 1 : 0;
  for (const auto& c : result.candidates)
    row.validation_diverged += c.completed ? 0 : 1;
  row.chosen = candidate_label(result.choice());
  const auto& p = result.parameter_fit.fitted;
  std::printf("   learned in %.1f s (parameter fit %.1f s: E %.4g, ν %.3f, α₀ %.3g, α₁ %.3g, "
              "observation rms %.3f %% -> %.3f %% of the diagonal = %.3g × the noise's, %s); "
              "chosen: %s; divergences in learning: %d in the fit, %d in the loop, %d in "
              "validation; fit probes that held no initial load: %d\n",
      row.learn_seconds, row.fit_seconds, p.young, p.poisson, p.alpha0, p.alpha1,
      100 * result.parameter_fit.initial_rms / o.diagonal,
      100 * result.parameter_fit.final_rms / o.diagonal, row.fit_over_noise,
      learn::to_string(result.parameter_fit.stop).c_str(), row.chosen.c_str(), row.fit_diverged,
      row.loop_diverged, row.validation_diverged, row.fit_unheld_loads);
  std::fflush(stdout);

  t0 = Clock::now();
  const TestErrors e = test_errors(result, motions.test, o.nominal, truth_test);
  row.err_nominal = e.nominal;
  row.err_fit = e.fit;
  row.err_learned = e.learned;
  row.test_diverged = (row.err_fit < 0 ? 1 : 0) + (row.err_learned < 0 ? 1 : 0);
  auto percent = [](double e) { return e < 0 ? err(e) : err(e) + " %"; };
  std::printf("   test err_L: nominal %s, parameter fit %s, learned %s (%.1f s)\n",
      percent(row.err_nominal).c_str(), percent(row.err_fit).c_str(),
      percent(row.err_learned).c_str(), seconds_since(t0));
  std::fflush(stdout);
  if (options.test_candidates)
    print_candidate_tests(result, motions.train, motions.test, o.nominal, truth_test,
        motions.test.mesh.bounding_box_diagonal());
  return row;
}

/// learned / baseline err_L: +∞ if the learned test diverged, NaN if the baseline's did (no ratio).
double learned_ratio(const RandomRow& r) {
  if (r.err_learned < 0)
    return std::numeric_limits<double>::infinity();
  if (r.err_fit < 0)
    return std::numeric_limits<double>::quiet_NaN();
  return r.err_fit > 0 ? r.err_learned / r.err_fit : (r.err_learned > 0 ? 1e9 : 1.0);
}

/// A fitted nominal whose training error is within this factor of the noise's RMS leaves the
/// data nothing a correction could be validated on (the diagnostic of target 2).
constexpr double kAboveNoise = 1.1;

/// The table and issue 19's targets, each PASS or FAIL.
void print_random_summary(const std::vector<RandomRow>& rows, int failed) {
  std::printf(
      "\n| case | tets | truth in family | observed | noise %% | deform. train/test %% | "
      "fit rms / noise rms | err_L nominal %% | err_L fit %% | err_L learned %% | learned/fit | "
      "chosen | learn s | fit s | diverged (fit/loop/validation/test) | initial load not held "
      "(fit) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& r : rows)
    std::printf(
        "| %d | %d | %s | %d (%.0f %%) | %.1f | %.1f / %.1f | %.3g | %s | %s | %s | %.3f | %s | "
        "%.1f | %.1f | %d / %d / %d / %d | %d |\n",
        r.index, r.tets, r.in_family ? "yes" : "no", r.observed, 100 * r.visible, r.noise,
        r.train_deformation, r.test_deformation, r.fit_over_noise, err(r.err_nominal).c_str(),
        err(r.err_fit).c_str(), err(r.err_learned).c_str(), learned_ratio(r), r.chosen.c_str(),
        r.learn_seconds, r.fit_seconds, r.fit_diverged, r.loop_diverged, r.validation_diverged,
        r.test_diverged, r.fit_unheld_loads);

  std::string violators;
  std::vector<double> ratios, ratios_above_noise;
  int learning_divergences = 0, test_divergences = 0, unheld_loads = 0;
  for (const auto& r : rows) {
    const double ratio = learned_ratio(r);
    if (!(ratio <= kNeverWorseFactor) && !std::isnan(ratio))
      violators += " " + std::to_string(r.index);
    if (!r.in_family && !std::isnan(ratio)) {
      ratios.push_back(ratio);
      if (r.fit_over_noise > kAboveNoise)
        ratios_above_noise.push_back(ratio);
    }
    learning_divergences += r.learning_divergences();
    test_divergences += r.test_diverged;
    unheld_loads += r.fit_unheld_loads;
  }
  std::printf("\n%zu case(s) ran, %d failed to run\n", rows.size(), failed);
  std::printf("target 1: learned err_L ≤ %.2f × the parameter fit's in every case: %s%s\n",
      kNeverWorseFactor, violators.empty() ? "PASS" : "FAIL (cases",
      violators.empty() ? "" : (violators + ")").c_str());
  if (ratios.empty())
    std::printf("target 2: median(learned / fit) ≤ 1/3 over truths outside the nominal's family: "
                "n/a (no such case)\n");
  else {
    const double m = median(ratios);
    std::printf("target 2: median(learned / fit) ≤ 1/3 over truths outside the nominal's family: "
                "%s (median %.3f over %zu case(s))\n",
        m <= 1.0 / 3 ? "PASS" : "FAIL", m, ratios.size());
    std::printf("  (diagnostic, not a target: median %.3f over the %zu of them whose fitted "
                "nominal leaves more than %.2f × the noise's RMS error in the training data)\n",
        ratios_above_noise.empty() ? std::nan("") : median(ratios_above_noise),
        ratios_above_noise.size(), kAboveNoise);
  }
  std::printf("target 3: no divergence in learning or in the test simulations: %s (%d in "
              "learning, %d in the fitted and learned test simulations)\n",
      learning_divergences + test_divergences == 0 ? "PASS" : "FAIL", learning_divergences,
      test_divergences);
  std::printf("  (not counted there: %d parameter-fit simulation(s) found no equilibrium under the "
              "training's recorded initial load, parameters its first frame rules out)\n",
      unheld_loads);
}

} // namespace

int run_random(const RandomRunOptions& options) {
  const int count = options.count, only = options.only;
  const bool draw_only = options.draw_only;
  const std::uint64_t seed = options.seed >= 0 ? static_cast<std::uint64_t>(options.seed)
                                               : std::random_device {}() & 0x7fffffffu;
  std::printf("bench_learning --random %d --seed %llu%s%s: %u hardware threads\n", count,
      static_cast<unsigned long long>(seed),
      only >= 0 ? (" --random-case " + std::to_string(only)).c_str() : "",
      options.noise_percent >= 0 ? (" --noise " + err(options.noise_percent)).c_str() : "",
      std::thread::hardware_concurrency());
  std::vector<RandomRow> rows;
  std::string skipped;
  int failed = 0, index = only >= 0 ? only : 0;
  const int last_index = only >= 0 ? only + 1 : 3 * count; // a bound on replacements
  const auto more = [&] { return only >= 0 || static_cast<int>(rows.size()) + failed < count; };
  for (; index < last_index && more(); ++index) {
    try {
      rows.push_back(run_random_case(seed, index, options));
      if (!draw_only && only < 0 && more())
        print_random_summary(rows, failed);
    } catch (const Undrawable& e) {
      std::printf("   SKIPPED (undrawable, not counted): %s\n", e.what());
      skipped += " " + std::to_string(index);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "random case %d failed: %s\n", index, e.what());
      std::printf("   FAILED TO RUN: %s\n", e.what());
      ++failed;
    }
  }
  if (!skipped.empty())
    std::printf("\nundrawable cases skipped:%s\n", skipped.c_str());
  if (!draw_only) {
    std::printf("\n== summary of seed %llu, %s\n", static_cast<unsigned long long>(seed),
        only >= 0 ? ("case " + std::to_string(only)).c_str()
                  : ("cases 0–" + std::to_string(index - 1)).c_str());
    print_random_summary(rows, failed);
  }
  return failed > 0 ? 1 : 0;
}

} // namespace bench_learning
