// The per-element stress and damping kernel (material/element_stress.hpp) through its three
// callers, on the clamped bar of bench_fem_step at 1.5k / 12k tets (E = 3e5, ν = 0.4, Rayleigh
// α₀ = 0.2, α₁ = 0.005) at one smoothly deformed, rotated and moving state (stretches about
// 1 ± 0.1):
//   ElasticForce/<material>: fem::ElasticForce::add_force, the simulator's hot path (forces and
//     the cache add_jacobian reuses). Materials: nominal; scaled = nominal with a per-element
//     stiffness scale in [0.5, 2]; rbf = nominal + the 40-centre RBF with damping of
//     bench/correction_cases.hpp (stress kernels; its Δα₁ floor −0.005 makes α₁ + Δα₁ ≥ 0 bind in
//     some elements).
//   CorrectionForce/rbf: learn::correction_force of that RBF (stress reconstruction's misfit).
//   CorrectionForceJacobian/rbf: learn::CorrectionForceJacobian::transposed over an RbfDesign on
//     the RBF's centres (the reconstruction's and the forward fit's operator).
// Args: size (0: 1.5k, 1: 12k tets), threads. With one thread the CPU column is the work itself
// (TBB runs it on the calling thread), robust to a loaded machine.
//
//   ./build/bench/bench_elastic_force --benchmark_filter='ElasticForce/.*/size:1/threads:1'
#include "correction_cases.hpp"

#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/learn/correction_force.hpp>

#include <support/bar_scene.hpp>

#include <benchmark/benchmark.h>
#include <cmath>
#include <random>
#include <string>
#include <tbb/global_control.h>

namespace {

using namespace elastolearn;

constexpr std::array<std::array<int, 3>, 2> kResolutions = { { { 16, 4, 4 }, { 32, 8, 8 } } };

sim::Scene bar(int size) {
  return test::bar_scene(
      { .cells = kResolutions[size], .young = 3e5, .alpha0 = 0.2, .alpha1 = 0.005 });
}

/// x = R (X + A X + bend) + c, v = W X + wave: stretches within about 1 ± 0.1, rates ~1/s.
struct State {
  VecX x, v;
};
State deformed(const mesh::TetMesh& mesh) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat3 A, W;
  for (int k = 0; k < 9; ++k) {
    A.data()[k] = 0.04 * u(rng);
    W.data()[k] = u(rng);
  }
  const Mat3 R = Eigen::Quaterniond(1.0, 0.2, -0.1, 0.3).normalized().toRotationMatrix();
  const Positions& X = mesh.rest_positions();
  State s { VecX(3 * X.rows()), VecX(3 * X.rows()) };
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Vec3 p = X.row(i).transpose();
    const double t = 10.0 * p[0];
    const Vec3 bend(0.0, 0.01 * std::sin(t), 0.01 * std::cos(t));
    s.x.segment<3>(3 * i) = R * (p + A * p + bend) + Vec3(0.1, -0.2, 0.05);
    s.v.segment<3>(3 * i) = W * p + Vec3(0.3 * std::cos(t), 0.2 * std::sin(2 * t), 0.1);
  }
  return s;
}

const material::RbfCorrection& rbf() {
  static const material::RbfCorrection c = bench::teacher_rbf(false);
  return c;
}

fem::MaterialModel material_named(const std::string& name, const sim::Scene& scene) {
  fem::MaterialModel m = scene.material;
  if (name == "scaled") {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(std::log(0.5), std::log(2.0));
    auto scales = std::make_shared<std::vector<double>>(scene.mesh.num_tets());
    for (double& s : *scales)
      s = std::exp(u(rng));
    m.stiffness_scale = scales;
  } else if (name == "rbf") {
    m.correction = rbf().clone();
  }
  return m;
}

void elastic_force(benchmark::State& state, std::string name) {
  tbb::global_control control(
      tbb::global_control::max_allowed_parallelism, static_cast<size_t>(state.range(1)));
  const sim::Scene scene = bar(static_cast<int>(state.range(0)));
  fem::ElasticForce force(scene.mesh, material_named(name, scene), scene.mass);
  const State s = deformed(scene.mesh);
  VecX f = VecX::Zero(s.x.size());
  for (auto _ : state) {
    force.add_force({ s.x, s.v }, f);
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["tets"] = scene.mesh.num_tets();
}

void correction_force(benchmark::State& state) {
  tbb::global_control control(
      tbb::global_control::max_allowed_parallelism, static_cast<size_t>(state.range(1)));
  const sim::Scene scene = bar(static_cast<int>(state.range(0)));
  const learn::ReconstructionMesh mesh(scene.mesh, scene.material);
  const State s = deformed(scene.mesh);
  for (auto _ : state) {
    VecX f = learn::correction_force(mesh, rbf(), s.x, s.v);
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["tets"] = scene.mesh.num_tets();
}

void correction_force_jacobian(benchmark::State& state) {
  tbb::global_control control(
      tbb::global_control::max_allowed_parallelism, static_cast<size_t>(state.range(1)));
  const sim::Scene scene = bar(static_cast<int>(state.range(0)));
  const learn::ReconstructionMesh mesh(scene.mesh, scene.material);
  const fem::DofMap dofs(scene.mesh.num_vertices(), scene.fixed_vertices);
  const learn::RbfDesign design(rbf().parameters().centres, learn::RbfFitOptions {});
  learn::CorrectionForceJacobian jacobian(mesh, dofs, design);
  const State s = deformed(scene.mesh);
  for (auto _ : state) {
    const MatX& jt = jacobian.transposed(s.x, s.v);
    benchmark::DoNotOptimize(jt.data());
  }
  state.counters["tets"] = scene.mesh.num_tets();
  state.counters["unknowns"] = design.num_unknowns();
}

void sizes_and_threads(benchmark::internal::Benchmark* b) {
  b->ArgNames({ "size", "threads" })->Unit(benchmark::kMillisecond);
  for (int size = 0; size < 2; ++size)
    for (int threads : { 1, 2 })
      b->Args({ size, threads });
}

void register_all() {
  for (const char* name : { "nominal", "scaled", "rbf" }) {
    const std::string label = std::string("ElasticForce/") + name;
    benchmark::RegisterBenchmark(label.c_str(), elastic_force, std::string(name))
        ->Apply(sizes_and_threads);
  }
  benchmark::RegisterBenchmark("CorrectionForce/rbf", correction_force)->Apply(sizes_and_threads);
  benchmark::RegisterBenchmark("CorrectionForceJacobian/rbf", correction_force_jacobian)
      ->Apply(sizes_and_threads);
}

} // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
