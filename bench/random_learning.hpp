#pragma once
// `bench_learning --random N --seed S [--random-case I] [--draw-only]` (issue 19): random cases
// drawn by random_cases.hpp, each learned by the one recipe (its default options unless an
// expert flag changes them, for every case alike).
#include <elastolearn/learn/learning_recipe.hpp>

#include <filesystem>

namespace bench_learning {

struct RandomRunOptions {
  int count = 0; ///< --random N: how many cases run
  int only = -1; ///< --random-case I: only case I (≥ 0)
  long seed = -1; ///< --seed S (−1: a fresh seed, printed)
  std::filesystem::path data; ///< where libcgal-demo's meshes are (random_cases.hpp)
  bool draw_only = false; ///< --draw-only: print the draws without simulating
  bool test_candidates = false; ///< --test-candidates: every validated candidate's test err_L
  /// --noise PCT: observation noise σ in % of the diagonal instead of the drawn level (every other
  /// draw unchanged), so that runs at two levels compare the same cases; −1: the drawn level.
  double noise_percent = -1;
  /// The recipe every case learns with: its defaults unless an expert flag changed them, alike
  /// for every case.
  elastolearn::learn::RecipeOptions recipe;
};

/// --random N / --random-case I: runs `count` random cases of the seed, or with `only` ≥ 0 only
/// case `only`, then prints the table and issue 19's targets. A case whose motions cannot be
/// drawn is skipped and, without `only`, replaced by the next index, so that `count` cases run.
/// Returns the exit status: non-zero only if a case failed to run.
int run_random(const RandomRunOptions& options);

} // namespace bench_learning
