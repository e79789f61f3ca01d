#pragma once
// The helpers bench_learning's named cases (bench_learning.cpp, paper 000's Table 1) and random
// cases (random_learning.cpp, issue 19) share: simulating the truth, err_L against it (of the
// nominal, fitted and learned models on the test motion), and the printouts of the learning's
// iterations and of its validated candidates.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/learn/iteration_record.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/sim/scene.hpp>

#include <string>
#include <vector>

namespace bench_learning {

using namespace elastolearn;

/// `s` with material `m`.
sim::Scene with_material(sim::Scene s, const fem::MaterialModel& m);

/// Max vertex displacement from rest over the trajectory, % of the diagonal.
double deformation(const std::vector<VecX>& frames, const mesh::TetMesh& mesh);

/// Forward simulation of a scene; throws if it does not complete (the truth must).
std::vector<VecX> simulate_or_throw(const sim::Scene& scene, const std::string& what);

/// err_L of `scene`'s simulation against the truth frames; −1 if it diverged.
double err_l(const sim::Scene& scene, const std::vector<VecX>& truth);

/// Test err_L [%] (−1: diverged) of the three models the benchmark compares.
struct TestErrors {
  double nominal = -1, fit = -1, learned = -1;
};

/// err_L on the test motion `test` (with the nominal material) against the truth's frames `truth`
/// of the nominal, of the recipe's parameter fit and of its learned material (`result.material` of
/// `given_nominal`), simulated in that order.
TestErrors test_errors(const learn::RecipeResult& result, const sim::Scene& test,
    const fem::MaterialModel& given_nominal, const std::vector<VecX>& truth);

/// A candidate's name as the printouts give it: its kind, then its iteration if it has one.
std::string candidate_label(const learn::Candidate& c);

/// --test-candidates: where the fitted nominal goes in the training motion ×
/// learn::kLargerMotion, then each validated candidate's validation RMS and test err_L (on `test`
/// against `truth`, errors as % of `size`), one line each.
void print_candidate_tests(const learn::RecipeResult& result, const sim::Scene& train,
    const sim::Scene& test, const fem::MaterialModel& given_nominal, const std::vector<VecX>& truth,
    double size);

/// One line per loop or forward-fit iteration (errors as % of `size`), indented by `indent`.
void print_iteration(const learn::IterationRecord& record, double size, const char* indent);

/// The recipe's callbacks that print its messages and its iterations (print_iteration, errors as %
/// of `size`), one line each, prefixed by `indent` (a string that outlives them).
learn::RecipeCallbacks printing_callbacks(double size, const char* indent);

/// A forward simulation that failed (a correction rejected as unstable was never simulated).
bool diverged(const learn::IterationRecord& r);

/// An err_L [%] as "%.3f", or "diverged" for err_l's −1.
std::string err(double e);

/// Issue 19's target 1: learned err_L ≤ this × the parameter fit's.
inline constexpr double kNeverWorseFactor = 1.05;

/// The median of `values` (non-empty).
double median(std::vector<double> values);

} // namespace bench_learning
