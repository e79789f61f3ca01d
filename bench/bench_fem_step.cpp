// Backward-Euler step cost on the clamped bar: 0.4 × 0.1 × 0.1 m of 6-tet cubes at about
// 1.5k / 12k / 53k tets, E = 3e5, ν = 0.4, ρ = 1000, α₀ = 0.2, α₁ = 0.005, gravity, dt = 1e-3,
// drooping from rest; Newton to 1e-6 relative residual. Reports ms per step, Newton iterations
// per step, and the share of time in assembly / factorisation / solve, per material, linear
// solver and thread count. The peer: Vega FEM 4.0 implicit backward Euler with Jacobi-PCG, one
// thread: 12 / 95 / 380 ms per step (corotated), 75 / 500 / 1750 ms (StVK).
//
//   ./build/bench/bench_fem_step --benchmark_filter='corotated/.*'   (subset)
//   ./build/bench/bench_fem_step --no-jacobian-reuse ...   (every Newton iteration assembles)
#include <elastolearn/core/timing.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <support/bar_scene.hpp>

#include <benchmark/benchmark.h>
#include <string>
#include <tbb/global_control.h>

extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace {

using namespace elastolearn;

bool g_jacobian_reuse = true;

constexpr std::array<std::array<int, 3>, 3> kResolutions
    = { { { 16, 4, 4 }, { 32, 8, 8 }, { 52, 13, 13 } } };

sim::Scene bar(material::ElasticModelType type, int resolution, sim::LinearSolverType solver) {
  sim::Scene s = test::bar_scene({ .cells = kResolutions[resolution],
      .model = type,
      .young = 3e5,
      .alpha0 = 0.2,
      .alpha1 = 0.005 });
  s.newton.relative_tolerance = 1e-6;
  if (!g_jacobian_reuse)
    s.newton.jacobian_reuse_contraction = 0;
  s.linear_solver = solver;
  return s;
}

void step_benchmark(
    benchmark::State& state, material::ElasticModelType type, sim::LinearSolverType solver) {
  const int resolution = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  tbb::global_control control(tbb::global_control::max_allowed_parallelism, threads);
  if (openblas_set_num_threads)
    openblas_set_num_threads(threads);
  sim::Simulator simulator(bar(type, resolution, solver));
  // Warm up past the first steps (whose Newton solves start far from the answer) as Vega's would.
  for (int i = 0; i < 3; ++i)
    simulator.step();
  long newton = 0, jacobians = 0, linear = 0, steps = 0;
  sim::SolverTimings timings;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const auto report = simulator.step();
    seconds += seconds_since(t0);
    if (!report.converged)
      state.SkipWithError(report.message.c_str());
    newton += report.iterations;
    jacobians += report.jacobians;
    linear += report.linear_iterations;
    timings += report.timings;
    ++steps;
  }
  state.counters["tets"] = simulator.scene().mesh.num_tets();
  state.counters["ms/step"] = 1e3 * seconds / steps;
  state.counters["newton/step"] = double(newton) / steps;
  state.counters["jacobians/step"] = double(jacobians) / steps;
  if (solver == sim::LinearSolverType::ConjugateGradient)
    state.counters["cg_it/step"] = double(linear) / steps;
  state.counters["assembly%"] = 100 * timings.assembly / seconds;
  state.counters["factor%"] = 100 * timings.factorization / seconds;
  state.counters["solve%"] = 100 * timings.solve / seconds;
}

void register_all() {
  using T = material::ElasticModelType;
  using S = sim::LinearSolverType;
  for (T type : { T::Corotated, T::StVK, T::NeoHookean })
    for (S solver : { S::Cholmod, S::ConjugateGradient }) {
      const std::string name = material::to_string(type) + "/" + sim::to_string(solver);
      auto* b = benchmark::RegisterBenchmark(name.c_str(), step_benchmark, type, solver);
      b->ArgNames({ "size", "threads" })->Unit(benchmark::kMillisecond)->UseRealTime();
      for (int size = 0; size < 3; ++size)
        for (int threads : { 1, 2 })
          b->Args({ size, threads });
      b->Iterations(10);
    }
}

} // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--no-jacobian-reuse") {
      g_jacobian_reuse = false;
      for (int j = i; j + 1 < argc; ++j)
        argv[j] = argv[j + 1];
      --argc;
      break;
    }
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
