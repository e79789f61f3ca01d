// Paper 000 Fig. 6 re-run: the distilled network's activation and batch normalisation. The same
// samples for every configuration (bench/correction_cases.hpp: 4000 training stretches
// 1 + 0.05·N(0, 1) per entry plus as many jittered, targets from the 40-centre RBF teacher),
// then per configuration: epochs, training time, the held-out (validation) RMS error relative to
// the teacher's N RMS, and the error on test stretches at growing deformation scale ‖σ − 1‖
// (the paper's right plot: the training data lie mostly below 0.15, all below ~0.3), each bin's
// RMS error relative to the teacher's RMS in that bin.
//   Stress networks (the paper's setting): {batch norm, none} × {ELU, ReLU, sigmoid}, 6-6, from
//   the stress-kernel teacher.
//   Energy networks (NnKind::Energy): squareplus, softplus, tanh, ELU, sigmoid, 8-8, no batch
//   norm, from the energy-kernel teacher, its tails as the polynomial (distill_rbf's default);
//   and squareplus with a least-squares polynomial (cubic, quadratic) or none.
// Prints a markdown table (docs/learning.md, "Activation and batch normalisation").
//
//   ./build/bench/bench_nn_activations
#include "correction_cases.hpp"

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

namespace {

using namespace elastolearn;

/// Test stretches at ‖σ − 1‖ uniform in [lo, hi], uniformly random directions.
std::vector<Vec3> shell(double lo, double hi, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) {
    Vec3 d(g(rng), g(rng), g(rng));
    out.push_back(Vec3::Ones() + u(rng) * d.normalized());
  }
  return out;
}

/// RMS ‖N − N_teacher‖ over `states`, relative to the teacher's RMS there.
double relative_error(const material::Correction& n, const material::Correction& teacher,
    const std::vector<Vec3>& states) {
  double err = 0, ref = 0;
  for (const Vec3& s : states) {
    const Vec3 t = teacher.correction(s, Vec3::Zero());
    err += (n.correction(s, Vec3::Zero()) - t).squaredNorm();
    ref += t.squaredNorm();
  }
  return std::sqrt(err / ref);
}

struct Config {
  const char* label;
  material::NnKind kind;
  material::Activation activation;
  bool batch_norm;
  /// Energy networks' polynomial: -1 the teacher's tails (distill_rbf's default), else the
  /// least-squares fit of this degree (NnDistillationOptions::energy_polynomial_degree).
  int polynomial_degree = -1;
  bool show_polynomial = false; ///< also print the polynomial alone's errors
};

} // namespace

int main() {
  const std::vector<std::pair<double, double>> bins { { 0, 0.15 }, { 0.15, 0.26 }, { 0.26, 0.4 },
    { 0.4, 0.6 } };
  std::vector<std::vector<Vec3>> tests;
  for (std::size_t b = 0; b < bins.size(); ++b)
    tests.push_back(shell(bins[b].first, bins[b].second, 2000, 100 + unsigned(b)));
  using A = material::Activation;
  using K = material::NnKind;
  const std::vector<Config> configs { { "BN + ELU", K::Stress, A::Elu, true },
    { "BN + ReLU", K::Stress, A::Relu, true }, { "BN + sigmoid", K::Stress, A::Sigmoid, true },
    { "ELU", K::Stress, A::Elu, false }, { "ReLU", K::Stress, A::Relu, false },
    { "sigmoid", K::Stress, A::Sigmoid, false },
    { "squareplus", K::Energy, A::Squareplus, false, -1, true },
    { "softplus", K::Energy, A::Softplus, false }, { "tanh", K::Energy, A::Tanh, false },
    { "ELU", K::Energy, A::Elu, false }, { "sigmoid", K::Energy, A::Sigmoid, false },
    { "squareplus, least-squares cubic polynomial", K::Energy, A::Squareplus, false, 3, true },
    { "squareplus, least-squares quadratic polynomial", K::Energy, A::Squareplus, false, 2, true },
    { "squareplus, no polynomial", K::Energy, A::Squareplus, false, 0 } };
  const material::RbfCorrection stress_teacher = bench::teacher_rbf(false);
  const material::RbfCorrection energy_teacher = bench::teacher_rbf(true);
  const MatX stretches = bench::training_stretches(4000, 7);
  std::printf("| network | configuration | epochs | training [s] | validation RMS |");
  for (const auto& [lo, hi] : bins)
    std::printf(" ‖σ−1‖ %.2f–%.2f |", lo, hi);
  std::printf("\n|---|---|---|---|---|");
  for (std::size_t b = 0; b < bins.size(); ++b)
    std::printf("---|");
  std::printf("\n");
  for (const Config& c : configs) {
    learn::RbfDistillationOptions o;
    o.kind = c.kind;
    learn::NnDistillationOptions& training = c.kind == K::Stress ? o.stress : o.energy;
    training.training.activation = c.activation;
    training.training.batch_norm = c.batch_norm;
    o.teacher_polynomial = c.polynomial_degree < 0;
    training.energy_polynomial_degree = std::max(c.polynomial_degree, 0);
    const material::RbfCorrection& teacher = c.kind == K::Stress ? stress_teacher : energy_teacher;
    try {
      const learn::NnDistillationResult r = learn::distill_rbf(teacher, stretches, o);
      std::printf("| %s | %s | %d | %.1f | %.2f %% |", material::to_string(c.kind).c_str(), c.label,
          r.training.epochs, r.training.seconds, 100 * r.relative_validation_rms());
      for (const auto& t : tests)
        std::printf(" %.2f %% |", 100 * relative_error(r.correction, teacher, t));
      std::printf("\n");
      if (c.show_polynomial) {
        // The polynomial alone (the MLP's output layer zeroed): what extrapolates.
        material::NnCorrection::Parameters p = r.correction.parameters();
        p.layers.back().weight.setZero();
        const material::NnCorrection poly(p);
        std::printf("| | (its polynomial alone) | | | |");
        for (const auto& t : tests)
          std::printf(" %.2f %% |", 100 * relative_error(poly, teacher, t));
        std::printf("\n");
      }
    } catch (const std::exception& e) {
      std::printf(
          "| %s | %s | failed: %s |\n", material::to_string(c.kind).c_str(), c.label, e.what());
    }
    std::fflush(stdout);
  }
  return 0;
}
