// Step cost of the springs simulators on hanging cloth n×n (8-neighbour springs):
// reference semi-implicit Euler vs the learned simulators (paper, corrected explicit,
// corrected implicit with direct and CG solvers). Counters: steps/s, springs, CG iterations.
#include <elastolearn/springs/implicit_simulator.hpp>
#include <elastolearn/springs/paper_tables.hpp>
#include <elastolearn/springs/reference_simulator.hpp>
#include <elastolearn/springs/stability.hpp>

#include <benchmark/benchmark.h>

using namespace elastolearn;
using namespace elastolearn::springs;

namespace {

LearnedSpring spring_for(double k) {
  return learn_paper_spring(k, ExperimentOptions {});
}

/// Run the stepper from the case's initial state; restart when the cloth has swung for 2 s so
/// the measured steps are representative of a swinging (not resting) cloth.
void run(benchmark::State& bench, SpringStepper& stepper, const StabilityCase& test) {
  SpringState s = test.initial;
  int since_restart = 0;
  for (auto _ : bench) {
    stepper.step(s);
    benchmark::DoNotOptimize(s.x.data());
    if (++since_restart == 200) {
      bench.PauseTiming();
      s = test.initial;
      since_restart = 0;
      bench.ResumeTiming();
    }
  }
  bench.counters["steps/s"]
      = benchmark::Counter(static_cast<double>(bench.iterations()), benchmark::Counter::kIsRate);
  bench.counters["springs"] = test.system.spring_count();
}

void BM_Reference(benchmark::State& bench) {
  const StabilityCase test = hanging_cloth_case(static_cast<int>(bench.range(0)));
  ReferenceSimulator sim(
      test.system, SpringLaw { SpringLawKind::linear, 1000.0, 1.0 }, 0.01, test.loads);
  run(bench, sim, test);
}

void BM_LearnedExplicit(benchmark::State& bench) {
  const StabilityCase test = hanging_cloth_case(static_cast<int>(bench.range(0)));
  ExplicitLearnedSimulator sim(test.system, spring_for(1000.0), 0.01, test.loads);
  run(bench, sim, test);
}

void BM_LearnedPaper(benchmark::State& bench) {
  const StabilityCase test = hanging_cloth_case(static_cast<int>(bench.range(0)));
  PaperSimulator sim(test.system, spring_for(1000.0), 0.01, test.loads);
  run(bench, sim, test);
}

/// Implicit: range(0) = n, range(1) = log10 k, range(2) = 0 direct / 1 CG.
void BM_LearnedImplicit(benchmark::State& bench) {
  const StabilityCase test = hanging_cloth_case(static_cast<int>(bench.range(0)));
  LearnedSimulatorOptions o;
  o.mode = LearnedMode::corrected_implicit;
  o.solver = bench.range(2) == 0 ? LinearSolverKind::direct : LinearSolverKind::cg;
  o.cg_tolerance = 1e-6;
  ImplicitLearnedSimulator sim(test.system,
      spring_for(std::pow(10.0, static_cast<double>(bench.range(1)))), 0.01, o, test.loads);
  long iterations = 0, steps = 0;
  SpringState s = test.initial;
  for (auto _ : bench) {
    sim.step(s);
    iterations += sim.last_step().cg_iterations;
    ++steps;
    if (steps % 200 == 0) {
      bench.PauseTiming();
      s = test.initial;
      bench.ResumeTiming();
    }
  }
  bench.counters["steps/s"]
      = benchmark::Counter(static_cast<double>(bench.iterations()), benchmark::Counter::kIsRate);
  bench.counters["cg_iters"] = steps ? static_cast<double>(iterations) / steps : 0.0;
  bench.counters["springs"] = test.system.spring_count();
}

} // namespace

BENCHMARK(BM_Reference)->Arg(25)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LearnedExplicit)->Arg(25)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LearnedPaper)->Arg(25)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LearnedImplicit)
    ->Args({ 25, 5, 0 })
    ->Args({ 25, 5, 1 })
    ->Args({ 100, 3, 1 })
    ->Args({ 100, 4, 1 })
    ->Args({ 100, 5, 1 })
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
