// The learned correction's cost, one core (issue 21: the network must evaluate ≥ 3× faster than
// the 40-kernel RBF with damping, and a step with it cost ≤ 1.2× the nominal step):
//   Element/<correction>: what fem::ElasticForce evaluates per element and force evaluation:
//     N(σ, ḟ) with ∂N/∂σ, ∂N/∂ḟ (correction_with_gradient) and Δα₁(σ) (stiffness_damping), over
//     1024 principal stretch states like a simulation's (1 ± 0.05, a few larger).
//     Variants: elastic = N with its gradient only, damping = Δα₁ only, both = the element's.
//   Step/<correction>: one backward-Euler step of the clamped bar (12k tets, E = 3e5, ν = 0.4,
//     α₀ = 0.2, α₁ = 0.005, gravity, Newton to 1e-6), one thread, nominal vs corrected: CPU ms
//     per step and per Newton iteration (the corrected material is ~20 % softer, so its steps
//     may take more Newton iterations than the nominal's: the per-iteration cost is the
//     correction's own).
// Corrections (bench/correction_cases.hpp): rbf_energy / rbf_stress = 40-centre RBF with damping
// (energy kernels as the recipe learns them / stress kernels), nn_energy / nn_stress = the
// networks distilled from them (squareplus 8-8 energy network; batch-norm + ELU 6-6 stress
// network); nn_energy_undamped = the energy network without the teacher's Δα₁; nominal_soft = the
// nominal model with E × 0.8 (the corrections soften it about that much).
//
//   ./build/bench/bench_correction --benchmark_filter='Element'   (subset)
#include "correction_cases.hpp"

#include <elastolearn/core/timing.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <support/bar_scene.hpp>

#include <benchmark/benchmark.h>
#include <cstdio>
#include <ctime>
#include <map>
#include <tbb/global_control.h>

extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace {

using namespace elastolearn;

constexpr int kStates = 1024;

/// Sorted principal stretches: 90 % 1 + 0.05·N(0, 1), 10 % uniform in [0.7, 1.3].
const std::vector<Vec3>& states() {
  static const std::vector<Vec3> out = [] {
    std::mt19937 rng(11);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> u(0.7, 1.3);
    std::vector<Vec3> v;
    for (int k = 0; k < kStates; ++k) {
      Vec3 s = k % 10 == 9 ? Vec3(u(rng), u(rng), u(rng))
                           : Vec3(1 + 0.05 * g(rng), 1 + 0.05 * g(rng), 1 + 0.05 * g(rng));
      std::sort(s.data(), s.data() + 3, std::greater<>());
      v.push_back(s);
    }
    return v;
  }();
  return out;
}

/// The corrections by name, built once (distillation takes a few seconds each).
const material::Correction& correction(const std::string& name) {
  static std::map<std::string, std::shared_ptr<const material::Correction>> cache;
  auto it = cache.find(name);
  if (it != cache.end())
    return *it->second;
  std::shared_ptr<const material::Correction> c;
  if (name == "rbf_energy" || name == "rbf_stress") {
    c = std::make_shared<material::RbfCorrection>(bench::teacher_rbf(name == "rbf_energy"));
  } else if (name == "nn_energy_undamped") {
    material::NnCorrection::Parameters p
        = dynamic_cast<const material::NnCorrection&>(correction("nn_energy")).parameters();
    p.damping.reset();
    c = std::make_shared<material::NnCorrection>(p);
  } else {
    const bool energy = name == "nn_energy";
    const auto r = bench::distilled(bench::teacher_rbf(energy));
    std::fprintf(stderr,
        "%s: distillation RMS %.2f %% of the teacher's N (validation), %d epochs\n", name.c_str(),
        100 * r.relative_validation_rms(), r.training.epochs);
    c = std::make_shared<material::NnCorrection>(r.correction);
  }
  return *cache.emplace(name, c).first->second;
}

enum Part { Elastic = 0, Damping = 1, Both = 2 };

void element(benchmark::State& state, std::string name) {
  const material::Correction& c = correction(name);
  const Part part = static_cast<Part>(state.range(0));
  const auto& s = states();
  const Vec3 rates(0.3, -0.1, 0.05);
  int k = 0;
  for (auto _ : state) {
    if (part != Damping) {
      Mat3 ds, dr;
      Vec3 n = c.correction_with_gradient(s[std::size_t(k)], rates, ds, dr);
      benchmark::DoNotOptimize(n);
      benchmark::DoNotOptimize(ds);
      benchmark::DoNotOptimize(dr);
    }
    if (part != Elastic) {
      double a = c.stiffness_damping(s[std::size_t(k)]);
      benchmark::DoNotOptimize(a);
    }
    k = (k + 1) & (kStates - 1);
  }
}

/// CPU time of the calling thread [s]: with TBB limited to one thread the step runs on it, and
/// neither the machine's load nor idle helper threads (BLAS) count.
double thread_cpu_seconds() {
  timespec t {};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

sim::Scene bar(double young) {
  sim::Scene s
      = test::bar_scene({ .cells = { 32, 8, 8 }, .young = young, .alpha0 = 0.2, .alpha1 = 0.005 });
  s.newton.relative_tolerance = 1e-6;
  return s;
}

void step(benchmark::State& state, std::string name) {
  tbb::global_control control(tbb::global_control::max_allowed_parallelism, 1);
  if (openblas_set_num_threads)
    openblas_set_num_threads(1);
  // nominal_soft: the nominal model 20 % softer, about what the corrections do to it, for the
  // Newton iteration count a softer material needs.
  sim::Scene scene = bar(name == "nominal_soft" ? 0.8 * 3e5 : 3e5);
  if (name != "nominal" && name != "nominal_soft")
    scene.material.correction = correction(name).clone();
  sim::Simulator simulator(scene);
  for (int i = 0; i < 3; ++i)
    simulator.step();
  long newton = 0, steps = 0;
  double seconds = 0, assembly = 0, cpu = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const double c0 = thread_cpu_seconds();
    const auto report = simulator.step();
    cpu += thread_cpu_seconds() - c0;
    seconds += seconds_since(t0);
    if (!report.converged)
      state.SkipWithError(report.message.c_str());
    newton += report.iterations;
    assembly += report.timings.assembly;
    ++steps;
  }
  state.counters["tets"] = simulator.scene().mesh.num_tets();
  // Thread CPU time: the step's work even on a loaded machine (wall time is not).
  state.counters["cpu_ms/step"] = 1e3 * cpu / double(steps);
  state.counters["cpu_ms/newton"] = 1e3 * cpu / double(newton);
  state.counters["newton/step"] = double(newton) / double(steps);
  state.counters["assembly%"] = 100 * assembly / seconds;
}

void register_all() {
  for (const char* name : { "rbf_energy", "rbf_stress", "nn_energy", "nn_stress" }) {
    const std::string label = std::string("Element/") + name;
    benchmark::RegisterBenchmark(label.c_str(), element, std::string(name))
        ->ArgName("part")
        ->Arg(Elastic)
        ->Arg(Damping)
        ->Arg(Both);
  }
  for (const char* name : { "nominal", "nominal_soft", "rbf_energy", "rbf_stress", "nn_energy",
           "nn_energy_undamped", "nn_stress" }) {
    const std::string label = std::string("Step/") + name;
    benchmark::RegisterBenchmark(label.c_str(), step, std::string(name))
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(10);
  }
}

} // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
