// Per-element material kernel cost, one core: the inversion-safe SVD (principal_frame), the stress
// P = U P̂ Vᵀ, the projected tangent dP/dF, and the whole element as fem/elastic_force.cpp runs it
// per Newton iteration (F, SVD, corrected principal stress, P, projected tangent, the 12×12 element
// matrix). Each iteration takes the next of 1024 deformation gradients (mild random, rotated,
// compressed, near-repeated and inverted), so branch prediction sees a realistic mix.
// Eigen's JacobiSVD is timed alongside as the reference the kernel replaces.
//
//   ./build-perf/bench/bench_material_kernel --benchmark_filter='Element'   (subset)
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/rbf_correction.hpp>
#include <elastolearn/material/svd3.hpp>

#include <Eigen/SVD>
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

namespace {

using namespace elastolearn;

constexpr int kStates = 1024;

Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

/// 1024 deformation gradients: 60% F = R (I + 0.1·noise) (a simulator's typical element), 15%
/// larger random stretches in [0.5, 2], 10% near-repeated, 10% compressed, 5% inverted.
const std::vector<Mat3>& states() {
  static const std::vector<Mat3> out = [] {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> u(-1, 1), s(0.5, 2.0);
    std::vector<Mat3> v;
    for (int k = 0; k < kStates; ++k) {
      const int kind = k % 20;
      const Mat3 R1 = random_rotation(rng), R2 = random_rotation(rng);
      Mat3 F;
      if (kind < 12) {
        Mat3 noise;
        for (int i = 0; i < 9; ++i)
          noise.data()[i] = 0.1 * u(rng);
        F = R1 * (Mat3::Identity() + noise);
      } else if (kind < 15) {
        F = R1 * Vec3(s(rng), s(rng), s(rng)).asDiagonal() * R2.transpose();
      } else if (kind < 17) {
        const double a = s(rng);
        F = R1 * Vec3(a, a * (1 + 1e-9 * u(rng)), s(rng)).asDiagonal() * R2.transpose();
      } else if (kind < 19) {
        F = R1 * Vec3(0.8 + 0.05 * u(rng), 0.7 + 0.05 * u(rng), 0.6 + 0.05 * u(rng)).asDiagonal()
            * R2.transpose();
      } else {
        F = R1 * Vec3(1.1, 0.9, -0.3 * (1 + 0.5 * u(rng))).asDiagonal() * R2.transpose();
      }
      v.push_back(F);
    }
    return v;
  }();
  return out;
}

const material::ElasticModel& corotated() {
  static const auto model = material::make_elastic_model(
      material::ElasticModelType::Corotated, material::Lame::from_young_poisson(3e5, 0.4));
  return *model;
}

struct Prepared {
  material::PrincipalFrame frame;
  material::CorrectedStress stress;
};

const std::vector<Prepared>& prepared() {
  static const std::vector<Prepared> out = [] {
    std::vector<Prepared> v;
    for (const Mat3& F : states()) {
      const auto frame = material::principal_frame(F);
      v.push_back({ frame,
          material::corrected_principal_stress(
              corotated(), nullptr, frame.stretches, Vec3::Zero()) });
    }
    return v;
  }();
  return out;
}

void BM_JacobiSvdReference(benchmark::State& state) {
  const auto& F = states();
  int k = 0;
  for (auto _ : state) {
    const Eigen::JacobiSVD<Mat3> svd(F[k], Eigen::ComputeFullU | Eigen::ComputeFullV);
    benchmark::DoNotOptimize(svd.singularValues().data());
    benchmark::DoNotOptimize(svd.matrixU().data());
    benchmark::DoNotOptimize(svd.matrixV().data());
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_JacobiSvdReference);

void BM_PrincipalFrame(benchmark::State& state) {
  const auto& F = states();
  int k = 0;
  for (auto _ : state) {
    auto frame = material::principal_frame(F[k]);
    benchmark::DoNotOptimize(frame);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_PrincipalFrame);

/// svd3 with its diagnostics: mean Jacobi sweeps and rotations per matrix, JacobiSVD fallbacks.
void BM_Svd3Diagnostics(benchmark::State& state) {
  const auto& F = states();
  int k = 0;
  double sweeps = 0, rotations = 0, fallbacks = 0;
  for (auto _ : state) {
    material::Svd3Info info;
    auto frame = material::svd3(F[k], &info);
    benchmark::DoNotOptimize(frame);
    sweeps += info.sweeps;
    rotations += info.rotations;
    fallbacks += info.fallback;
    k = (k + 1) & (kStates - 1);
  }
  state.counters["sweeps"] = benchmark::Counter(sweeps, benchmark::Counter::kAvgIterations);
  state.counters["rotations"] = benchmark::Counter(rotations, benchmark::Counter::kAvgIterations);
  state.counters["fallbacks"] = benchmark::Counter(fallbacks, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_Svd3Diagnostics);

void BM_FirstPiola(benchmark::State& state) {
  const auto& in = prepared();
  int k = 0;
  for (auto _ : state) {
    Mat3 P = material::first_piola(in[k].frame, in[k].stress.stress);
    benchmark::DoNotOptimize(P);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_FirstPiola);

void BM_FirstPiolaDerivative(benchmark::State& state) {
  const bool project = state.range(0) != 0;
  const auto& in = prepared();
  int k = 0;
  for (auto _ : state) {
    Mat9 H = material::first_piola_derivative(
        in[k].frame, in[k].stress.stress, in[k].stress.d_stretches, project);
    benchmark::DoNotOptimize(H);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_FirstPiolaDerivative)->ArgName("project_psd")->Arg(0)->Arg(1);

/// The target number: SVD + principal stress + P + projected dP/dF of one element.
void BM_SvdStressTangent(benchmark::State& state) {
  const auto& F = states();
  const auto& model = corotated();
  int k = 0;
  for (auto _ : state) {
    const auto frame = material::principal_frame(F[k]);
    const auto stress
        = material::corrected_principal_stress(model, nullptr, frame.stretches, Vec3::Zero());
    Mat3 P = material::first_piola(frame, stress.stress);
    Mat9 H = material::first_piola_derivative(frame, stress.stress, stress.d_stretches, true);
    benchmark::DoNotOptimize(P);
    benchmark::DoNotOptimize(H);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_SvdStressTangent);

/// Rest data of the unit right-angled tet (vertices 0, e_x, e_y, e_z).
fem::TetRestData unit_tet_rest() {
  fem::TetRestData rest;
  rest.volume = 1.0 / 6.0;
  rest.gradients << -1, 1, 0, 0, -1, 0, 1, 0, -1, 0, 0, 1;
  return rest;
}

/// Projected element stiffness through the 9×9 dP/dF (first_piola_derivative, then
/// element_matrix_from_tangent on its upper triangle).
void BM_ElementMatrixFromTangent(benchmark::State& state) {
  const auto& in = prepared();
  const fem::TetRestData rest = unit_tet_rest();
  int k = 0;
  for (auto _ : state) {
    const Mat9 H = material::first_piola_derivative(
        in[k].frame, in[k].stress.stress, in[k].stress.d_stretches, true);
    benchmark::DoNotOptimize(H);
    Mat12 K = fem::element_matrix_from_tangent(H, rest, true);
    benchmark::DoNotOptimize(K);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_ElementMatrixFromTangent);

/// The same matrix straight from the eigen-form tangent (fem::element_stiffness), as
/// fem/elastic_force.cpp computes it.
void BM_ElementStiffness(benchmark::State& state) {
  const auto& in = prepared();
  const fem::TetRestData rest = unit_tet_rest();
  int k = 0;
  for (auto _ : state) {
    const auto tangent = material::principal_tangent(
        in[k].frame, in[k].stress.stress, in[k].stress.d_stretches, true);
    Mat12 K = fem::element_stiffness(in[k].frame, tangent, rest);
    benchmark::DoNotOptimize(K);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_ElementStiffness);

/// The whole per-element Newton-iteration kernel of fem/elastic_force.cpp (no correction, no
/// damping): F from the vertex positions, cold SVD, stress, P, force, projected tangent, 12×12
/// matrix.
void BM_Element(benchmark::State& state) {
  const auto& F = states();
  const auto& model = corotated();
  const fem::TetRestData rest = unit_tet_rest();
  // Vertex positions realising each F on the unit corner tet: x_a = F X_a.
  std::vector<Eigen::Matrix<double, 3, 4>> x(kStates);
  Eigen::Matrix<double, 3, 4> X;
  X << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  for (int k = 0; k < kStates; ++k)
    x[k] = F[k] * X;
  int k = 0;
  for (auto _ : state) {
    const auto frame = material::principal_frame(fem::deformation_gradient(x[k], rest));
    const auto stress
        = material::corrected_principal_stress(model, nullptr, frame.stretches, Vec3::Zero());
    const Mat3 P = material::first_piola(frame, stress.stress);
    Eigen::Matrix<double, 3, 4> force = -rest.volume * P * rest.gradients;
    const auto tangent
        = material::principal_tangent(frame, stress.stress, stress.d_stretches, true);
    Mat12 K = fem::element_stiffness(frame, tangent, rest);
    benchmark::DoNotOptimize(force);
    benchmark::DoNotOptimize(K);
    k = (k + 1) & (kStates - 1);
  }
}
BENCHMARK(BM_Element);

/// A learned RBF correction N(σ) with its stretch gradient, as every element evaluates it per
/// force evaluation during learning: m centres (the learning default is 40) spread like stretch
/// samples (1 ± 0.05), a quadratic tail, weights of realistic size; the state's stretches.
void BM_RbfCorrectionWithGradient(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  material::RbfCorrection::Parameters p;
  p.centres.resize(m, 3);
  p.weights.resize(m);
  for (int i = 0; i < m; ++i) {
    p.centres.row(i) = Eigen::RowVector3d(1 + 0.05 * n(rng), 1 + 0.05 * n(rng), 1 + 0.05 * n(rng));
    p.weights[i] = 1e3 * n(rng);
  }
  p.own_slope = 5e3;
  p.quadratic = Eigen::Vector4d(3e4, -2e4, 1e4, 4e4);
  const material::RbfCorrection correction(p);
  const auto& in = prepared();
  int k = 0;
  for (auto _ : state) {
    Mat3 ds, dr;
    Vec3 N = correction.correction_with_gradient(in[k].frame.stretches, Vec3::Zero(), ds, dr);
    benchmark::DoNotOptimize(N);
    benchmark::DoNotOptimize(ds);
    k = (k + 1) & (kStates - 1);
  }
  state.counters["time/kernel"]
      = benchmark::Counter(3.0 * m * static_cast<double>(state.iterations()),
          benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RbfCorrectionWithGradient)->ArgName("centres")->Arg(40)->Arg(160);

} // namespace

BENCHMARK_MAIN();
