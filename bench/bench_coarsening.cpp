// The coarsening benchmark of issue 20 (paper 000 §7.3, Fig. 17, Table 1's "Bar
// (Heterogenous)" row): a fine bar (34 × 8 × 8 cells) of layers E = 1e5 / 1e7 Pa alternating
// along its axis, and a coarse bar (17 × 4 × 4 cells) with one homogeneous corotated nominal.
// The scenes are examples/09_coarsening's (one source for both); this program runs the same
// pipeline as its run.sh through library calls:
//   1. simulate the fine bar's four motions (training bend and twist, test bend and twist);
//   2. observe each at every coarse vertex (io::observe_trajectory with `onto`, what
//      `observe --onto --all` runs);
//   3. fit E, ν, α₀, α₁ of the coarse nominal to both training motions at once (what
//      `fit-parameters training.json` runs): the best homogeneous material;
//   4. learn with the one recipe and its default options (learn::learn_material, `learn
//      training.json`);
//   5. simulate the coarse test scenes with the nominal, the fitted and the learned material and
//      measure err_L against the observed fine motion (learn::observation_error, what `evaluate
//      --truth obs.h5` measures): the max vertex error over all frames, % of the bar's diagonal.
// It prints what it measured; the paper's Table 1 gives 0.2 % (bend) / 0.5 % (twist).
//
//   bench_coarsening [--scenes DIR]      (default: examples/09_coarsening of the source tree)
//
// A plain program with a table printout (not Google Benchmark): it runs once, for minutes.
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_observation.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace {

using namespace elastolearn;

/// One motion: the fine truth observed at the coarse scene's vertices.
struct CoarseMotion {
  std::string name;
  io::SceneFile coarse;
  observe::Observation observed;
  double seconds_fine = 0; ///< the fine simulation's wall time
};

CoarseMotion observe_motion(const std::filesystem::path& dir, const std::string& name) {
  CoarseMotion m;
  m.name = name;
  const io::SceneFile fine = io::read_scene_file(dir / ("fine_" + name + ".json"));
  m.coarse = io::read_scene_file(dir / ("coarse_" + name + ".json"));
  const auto start = Clock::now();
  sim::ForwardRun run = sim::simulate_positions(fine.scene);
  m.seconds_fine = seconds_since(start);
  if (!run.completed)
    throw InputError(name, "the fine simulation failed: " + run.message);
  io::TrajectoryData trajectory;
  trajectory.rest_positions = fine.scene.mesh.rest_positions();
  trajectory.tets = fine.scene.mesh.tets();
  for (size_t t = 0; t < run.positions.size(); ++t) {
    trajectory.positions.push_back(unflatten(run.positions[t]));
    trajectory.time.push_back(fine.scene.initial.time + static_cast<double>(t) * fine.scene.dt);
  }
  io::ObservationRequest request;
  request.all_vertices = true;
  request.onto = &m.coarse.scene.mesh;
  request.onto_source = m.coarse.path.string();
  m.observed = io::observe_trajectory(trajectory, name, request).observation;
  std::printf("%-12s fine %d tets, %d frames simulated in %.1f s; observed at %d coarse vertices\n",
      name.c_str(), fine.scene.mesh.num_tets(), fine.scene.frames, m.seconds_fine,
      m.observed.num_observed());
  std::fflush(stdout);
  return m;
}

/// err_L [%] of the coarse scene simulated with `material` against the observed fine motion; −1
/// if the simulation diverged.
double err_l(const CoarseMotion& m, const fem::MaterialModel& material) {
  sim::Scene scene = m.coarse.scene;
  scene.material = material;
  const sim::ForwardRun run = sim::simulate_positions(scene);
  if (!run.completed) {
    std::printf("   (%s diverged: %s)\n", m.name.c_str(), run.message.c_str());
    return -1;
  }
  return learn::as_percent_of(
      learn::observation_error(run.positions, m.observed), scene.mesh.bounding_box_diagonal())
      .max;
}

} // namespace

int main(int argc, char** argv) {
  std::filesystem::path dir
      = std::filesystem::path(ELASTOLEARN_SOURCE_DIR) / "examples" / "09_coarsening";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--scenes") == 0 && i + 1 < argc) {
      dir = argv[++i];
    } else {
      std::printf(
          "usage: bench_coarsening [--scenes DIR]   (the scenes of examples/09_coarsening)\n");
      return std::strcmp(argv[i], "--help") == 0 ? 0 : 2;
    }
  }
  try {
    const auto start = Clock::now();
    std::vector<CoarseMotion> motions;
    for (const char* name : { "train_bend", "train_twist", "test_bend", "test_twist" })
      motions.push_back(observe_motion(dir, name));
    const double seconds_truth = seconds_since(start);
    std::vector<learn::Motion> training;
    for (int i = 0; i < 2; ++i)
      training.push_back({ motions[i].name, motions[i].coarse.scene, motions[i].observed });
    const fem::MaterialModel& nominal = training.front().scene.material;

    // The best homogeneous material: E, ν, α₀, α₁ fitted to both training motions.
    auto stage = Clock::now();
    material::ElasticModelType type {};
    const learn::NominalParameters start_parameters = learn::nominal_parameters_of(nominal, type);
    const learn::ParameterFitReport fit
        = learn::fit_parameters(training, type, start_parameters, learn::ParameterFitOptions {});
    const double seconds_fit = seconds_since(stage);
    const fem::MaterialModel fitted
        = learn::scene_with_parameters(training.front().scene, type, fit.fitted).material;
    std::printf("fitted to both training motions: E %.4g Pa, nu %.4f, alpha0 %.3g 1/s, alpha1 "
                "%.3g s (%s, %.1f s)\n",
        fit.fitted.young, fit.fitted.poisson, fit.fitted.alpha0, fit.fitted.alpha1,
        learn::to_string(fit.stop).c_str(), seconds_fit);
    std::fflush(stdout);

    // The one recipe, default options.
    stage = Clock::now();
    learn::RecipeCallbacks callbacks;
    callbacks.message = [](const std::string& line) {
      std::printf("  learn: %s\n", line.c_str());
      std::fflush(stdout);
    };
    const learn::RecipeResult learned = learn::learn_material(training, {}, callbacks);
    const double seconds_learn = seconds_since(stage);
    const fem::MaterialModel learned_material = learned.material(nominal);
    const learn::NominalParameters& recipe_fit = learned.parameter_fit.fitted;
    std::printf("learned: %s chosen (recipe's own fit E %.4g Pa, nu %.4f; validation on %s), "
                "%.1f s\n",
        learn::to_string(learned.choice().kind).c_str(), recipe_fit.young, recipe_fit.poisson,
        learned.validation_data.c_str(), seconds_learn);

    std::printf("\nerr_L (max vertex error over the motion, %% of the bar's diagonal %.4g m), "
                "against the fine motion at the coarse vertices:\n",
        motions.front().coarse.scene.mesh.bounding_box_diagonal());
    std::printf("%-12s %12s %12s %12s   (paper 000 Table 1: learned 0.2 / 0.5)\n", "motion",
        "nominal", "fitted", "learned");
    for (const CoarseMotion& m : motions) {
      std::printf("%-12s %12.4f %12.4f %12.4f\n", m.name.c_str(), err_l(m, nominal),
          err_l(m, fitted), err_l(m, learned_material));
      std::fflush(stdout);
    }
    std::printf("\ntimes: fine truth (4 motions) %.1f s, parameter fit %.1f s, learning %.1f s, "
                "total %.1f s\n",
        seconds_truth, seconds_fit, seconds_learn, seconds_since(start));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_coarsening: %s\n", e.what());
    return 1;
  }
  return 0;
}
