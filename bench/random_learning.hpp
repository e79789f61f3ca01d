#pragma once
// `bench_learning --random N --seed S [--random-case I] [--draw-only]` (issue 19): random cases
// drawn by random_cases.hpp, each learned by the one recipe with its default options.
#include <filesystem>

namespace bench_learning {

/// --random N / --random-case I: runs `count` random cases of the seed `seed_option` (−1: a fresh
/// seed, printed), or with `only` ≥ 0 only case `only`, then prints the table and issue 19's
/// targets; `draw_only` prints the draws without simulating. A case whose motions cannot be
/// drawn is skipped and, without `only`, replaced by the next index, so that `count` cases run.
/// `data`: where libcgal-demo's meshes are (random_cases.hpp); `test_candidates`: also print every
/// validated candidate's test err_L. Returns the exit status: non-zero only if a case failed to
/// run.
int run_random(int count, int only, const std::filesystem::path& data, bool draw_only,
    long seed_option, bool test_candidates);

} // namespace bench_learning
