#pragma once
/// \file The learned corrections the correction benchmarks time and compare: a 40-centre RBF
/// with damping as the learning recipe learns it (energy kernels, an isotropic linear + quadratic
/// tail of a ~20 % too stiff nominal, stiffness-damping kernels), the same with stress kernels,
/// and the networks distilled from them (learn::distill_rbf). Centres and training stretches
/// spread like a learning run's (1 ± 0.05 per stretch); weights of a realistic size for E = 3e5.
#include <elastolearn/learn/nn_distillation.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <random>

namespace elastolearn::bench {

/// n × 3 stretches 1 + 0.05 · N(0, 1) per entry.
inline MatX training_stretches(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  MatX s(n, 3);
  for (Eigen::Index i = 0; i < s.size(); ++i)
    s.data()[i] = 1 + 0.05 * g(rng);
  return s;
}

/// The 40-centre (`centres`) RBF with damping, stress-free at rest; energy or stress kernels.
inline material::RbfCorrection teacher_rbf(bool energy_kernels, int centres = 40) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  material::RbfCorrection::Parameters p;
  p.energy_kernels = energy_kernels;
  p.epsilon = 1e-3;
  p.centres.resize(centres, 3);
  p.weights.resize(centres);
  p.damping_weights.resize(centres);
  for (int i = 0; i < centres; ++i) {
    p.centres.row(i) = Eigen::RowVector3d(1 + 0.05 * g(rng), 1 + 0.05 * g(rng), 1 + 0.05 * g(rng));
    p.weights[i] = (energy_kernels ? 1e3 : 6e3) * g(rng);
    p.damping_weights[i] = 2e-4 * g(rng);
  }
  p.own_slope = -5e4;
  p.other_slope = -2e4;
  p.quadratic = Eigen::Vector4d(3e4, 2e4, 1e4, -1e4); // q₁ = 2 q₂: an energy tail
  p.damping_constant = 1e-3;
  p.damping_slopes = Vec3(2e-3, 0, 0);
  p.damping_floor = -0.005;
  // Stress-free at rest, as the recipe learns it (RbfFitOptions::stress_free_rest): the constant
  // cancels the kernels' N(1, 1, 1) (equal components there by isotropy).
  p.constant = -material::RbfCorrection(p).correction(Vec3::Ones(), Vec3::Zero())[0];
  return material::RbfCorrection(p);
}

/// The network distilled from `teacher` on 4000 training stretches (+ as many jittered):
/// learn::distill_rbf's default kind for the teacher unless `kind` is given.
inline learn::NnDistillationResult distilled(
    const material::RbfCorrection& teacher, std::optional<material::NnKind> kind = std::nullopt) {
  learn::RbfDistillationOptions o;
  o.kind = kind;
  return learn::distill_rbf(teacher, training_stretches(4000, 7), o);
}

} // namespace elastolearn::bench
