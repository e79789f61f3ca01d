// The helpers bench_learning's named cases (bench_learning.cpp) and random cases
// (random_learning.cpp) share. Declarations and their documentation: learning_bench_support.hpp.
#include "learning_bench_support.hpp"

#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/material_stability.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/learn/trajectory_error.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <algorithm>
#include <cstdio>
#include <variant>

namespace bench_learning {

sim::Scene with_material(sim::Scene s, const fem::MaterialModel& m) {
  s.material = m;
  return s;
}

double deformation(const std::vector<VecX>& frames, const mesh::TetMesh& mesh) {
  const VecX rest = flatten(mesh.rest_positions());
  double worst = 0;
  for (const auto& x : frames)
    for (Eigen::Index v = 0; v < x.size() / 3; ++v)
      worst = std::max(worst, (x.segment<3>(3 * v) - rest.segment<3>(3 * v)).norm());
  return 100 * worst / mesh.bounding_box_diagonal();
}

std::vector<VecX> simulate_or_throw(const sim::Scene& scene, const std::string& what) {
  auto run = sim::simulate_positions(scene);
  if (!run.completed)
    throw InputError(what, "simulation failed: " + run.message);
  return std::move(run.positions);
}

double err_l(const sim::Scene& scene, const std::vector<VecX>& truth) {
  const auto run = sim::simulate_positions(scene);
  if (!run.completed) {
    std::fprintf(stderr, "   (diverged: %s)\n", run.message.c_str());
    return -1;
  }
  return learn::as_percent_of(
      learn::position_error(run.positions, truth), scene.mesh.bounding_box_diagonal())
      .max;
}

TestErrors test_errors(const learn::RecipeResult& result, const sim::Scene& test,
    const fem::MaterialModel& given_nominal, const std::vector<VecX>& truth) {
  TestErrors e;
  e.nominal = err_l(test, truth);
  e.fit = err_l(
      learn::scene_with_parameters(test, result.nominal_type, result.parameter_fit.fitted), truth);
  e.learned = err_l(with_material(test, result.material(given_nominal)), truth);
  return e;
}

std::string candidate_label(const learn::Candidate& c) {
  std::string label = learn::to_string(c.kind);
  if (c.iteration >= 0) // append, not " " + to_string(): GCC 12 warns -Wrestrict on that wrongly
    label.append(" ").append(std::to_string(c.iteration));
  return label;
}

void print_candidate_tests(const learn::RecipeResult& result, const sim::Scene& train,
    const sim::Scene& test, const fem::MaterialModel& given_nominal, const std::vector<VecX>& truth,
    double size) {
  // Where the fitted nominal goes in the larger motion (the learned candidates' check).
  const auto larger = sim::simulate_positions(
      sim::amplified_scene(with_material(train, result.fitted_nominal), learn::kLargerMotion));
  if (larger.completed) {
    const MatX s
        = learn::collect_stretches(learn::ReconstructionMesh(train.mesh), larger.positions);
    std::printf("   fitted nominal in the training motion ×%.1f: s₁ up to %.3f, s₃ down to %.3f\n",
        learn::kLargerMotion, s.col(0).maxCoeff(), s.col(2).minCoeff());
  }
  // Where the test goes: a learned candidate unstable there can diverge in it.
  const MatX test_stretches = learn::collect_stretches(learn::ReconstructionMesh(test.mesh), truth);
  for (size_t i = 0; i < result.candidates.size(); ++i) {
    const learn::Candidate& c = result.candidates[i];
    const std::string name = candidate_label(c);
    const double test_error = c.completed
        ? err_l(with_material(test, result.material(given_nominal, int(i))), truth)
        : -1;
    const auto& x = c.larger_motion;
    std::printf("   candidate %-22s validation rms %.4f %%, z %+.1f (resolution %.1f, training z "
                "%+.1f), %s (larger motion and droop: %s); test err_L %.3f %%%s\n",
        name.c_str(), 100 * c.validation.rms / size, c.significance, c.resolution,
        c.training_significance, c.eligible() ? "eligible" : "not eligible",
        !x.checked ? "not checked" : (x.completed ? "passed" : x.message.c_str()), test_error,
        int(i) == result.chosen ? "  <- chosen" : "");
    if (c.completed && c.kind != learn::CandidateKind::Nominal
        && c.kind != learn::CandidateKind::FittedNominal) {
      const fem::MaterialModel m = result.material(given_nominal, int(i));
      const learn::StabilityReport s
          = learn::material_stability(*m.elastic, m.correction.get(), test_stretches);
      const Vec3& w = s.worst_stretches;
      std::printf("      at the truth's test stretches: unstable at %ld of %ld, smallest stiffness "
                  "%.3f × the nominal's at σ = (%.3f, %.3f, %.3f)\n",
          s.unstable_samples, s.samples, s.min_relative_eigenvalue, w(0), w(1), w(2));
    }
  }
  std::fflush(stdout);
}

void print_iteration(const learn::IterationRecord& record, double size, const char* indent) {
  const learn::ForwardOutcome& f = learn::forward_of(record);
  if (f.completed())
    std::printf("%siteration %d: forward rms %.4f %%, max %.4f %%", indent,
        learn::iteration_of(record), 100 * f.error().rms / size, 100 * f.error().max / size);
  else
    std::printf("%siteration %d:", indent, learn::iteration_of(record));
  if (const auto* step = learn::forward_fit_of(record))
    std::printf(" (forward fit: %s, %d kernels, %.1f s%s%s)\n",
        f.status() == learn::ForwardStatus::unstable ? "trial unstable, rejected unsimulated"
            : !f.completed()                         ? "trial DIVERGED, rejected"
            : step->accepted                         ? "accepted"
                                                     : "rejected",
        step->centres, f.seconds(), f.completed() ? "" : ": ", f.message().c_str());
  else if (const auto* t = learn::stages_of(record))
    std::printf(
        "; %d modes, %d kernels, control force %.3e N, misfit %.2e / %.2e N, %d cuts, step kept "
        "%.3g; "
        "forward %.1f s, constrained %.1f s, space-time %.1f s (%d GN), reconstruction %.1f s\n",
        t->modes, t->centres, t->control_force_rms, t->correction_misfit, t->correction_target,
        t->stability_cuts, t->step_kept, f.seconds(), t->seconds_constrained, t->seconds_space_time,
        t->space_time_iterations, t->seconds_reconstruction);
  else if (!f.completed())
    std::printf(" -> this correction's forward simulation DIVERGED (%.1f s: %s); %s\n", f.seconds(),
        f.message().c_str(),
        std::get<learn::LoopRecord>(record).damped_update() ? "trying half its step"
                                                            : "the loop stops");
  else if (std::get<learn::LoopRecord>(record).damped_update())
    std::printf(" (no better than the best, %.1f s): trying half its step\n", f.seconds());
  else
    std::printf(" (final forward check, %.1f s)\n", f.seconds());
  std::fflush(stdout);
}

learn::RecipeCallbacks printing_callbacks(double size, const char* indent) {
  learn::RecipeCallbacks callbacks;
  callbacks.message = [indent](const std::string& line) {
    std::printf("%s%s\n", indent, line.c_str());
    std::fflush(stdout);
  };
  callbacks.loop.iteration
      = [size, indent](const learn::IterationRecord& r) { print_iteration(r, size, indent); };
  return callbacks;
}

bool diverged(const learn::IterationRecord& r) {
  return learn::forward_of(r).status() == learn::ForwardStatus::diverged;
}

std::string err(double e) {
  char buf[32];
  if (e < 0)
    return "diverged";
  std::snprintf(buf, sizeof buf, "%.3f", e);
  return buf;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

} // namespace bench_learning
