#include <elastolearn/springs/paper_tables.hpp>
#include <elastolearn/springs/stability.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::springs;

namespace {
std::function<StepperFactory(double)> model(int which) {
  return [which](double k) -> StepperFactory {
    SpringLaw law;
    law.k = k;
    if (which < 0)
      return reference_factory(law, 0.01);
    LearnedSimulatorOptions o;
    o.mode = static_cast<LearnedMode>(which);
    return learned_factory(learn_paper_spring(k, ExperimentOptions {}), o);
  };
}
} // namespace

TEST(Stability, SingleSpringLimitsMatchTheAnalysis) {
  StabilityOptions o;
  o.k_max = 1e6;
  o.steps = 300;
  o.resolution = 1.02;
  const StabilityCase test = single_spring_case();
  // Semi-implicit Euler: stable iff k dt² < 4; the paper's step: trace 2(1 − k dt²), det 1,
  // stable iff k dt² < 2 — a single learned spring is LESS stable than the reference.
  const StabilityResult ref = find_stability_limit(model(-1), test, o);
  // Near the limit the growth per step is tiny, so a finite run brackets it within a few %.
  EXPECT_LE(ref.largest_stable, 4e4 * 1.05);
  EXPECT_GE(ref.smallest_unstable, 4e4 / 1.05);
  const StabilityResult paper
      = find_stability_limit(model(static_cast<int>(LearnedMode::paper)), test, o);
  EXPECT_LE(paper.largest_stable, 2e4 * 1.05);
  EXPECT_GE(paper.smallest_unstable, 2e4 / 1.05);
  // The corrected explicit mode inherits the reference limit exactly.
  const StabilityResult expl
      = find_stability_limit(model(static_cast<int>(LearnedMode::corrected_explicit)), test, o);
  EXPECT_DOUBLE_EQ(expl.largest_stable, ref.largest_stable);
}

TEST(Stability, PaperClothIsMoreStableOnlyBecauseItIsSofter) {
  StabilityOptions o;
  o.k_max = 1e5;
  o.steps = 300;
  o.resolution = 1.1;
  const StabilityCase cloth = hanging_cloth_case(5);
  const StabilityResult ref = find_stability_limit(model(-1), cloth, o);
  const StabilityResult paper
      = find_stability_limit(model(static_cast<int>(LearnedMode::paper)), cloth, o);
  EXPECT_GT(paper.largest_stable, 2.0 * ref.largest_stable);
}
