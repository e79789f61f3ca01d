#pragma once
/// \file Deformation gradients for material tests: rest, rotations, random, large stretch,
/// near-inverted, inverted and (near-)repeated stretches, each built as F = R₁ diag(σ) R₂ᵀ with
/// seeded random rotations so that every test sees the same states.
/// Stretch values avoid the kinks that finite differences cannot resolve (the neo-Hookean
/// inversion threshold 0.1, the knots of the test splines in test_elastic_models.cpp) by more
/// than the FD stencil width (2·1e-4).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <random>
#include <string>
#include <vector>

namespace elastolearn::test {

struct MaterialState {
  std::string name;
  Eigen::Matrix3d F;
};

/// A uniformly distributed rotation from a seeded generator.
inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// F = R₁ diag(stretches) R₂ᵀ with rotations drawn from `seed`.
inline Eigen::Matrix3d rotated_stretch(const Eigen::Vector3d& stretches, unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::Matrix3d R1 = random_rotation(rng), R2 = random_rotation(rng);
  return R1 * stretches.asDiagonal() * R2.transpose();
}

/// Column-major vec of a 3×3 matrix and its inverse (core/types.hpp convention).
inline Eigen::VectorXd vec(const Eigen::Matrix3d& M) {
  return Eigen::Map<const Eigen::Matrix<double, 9, 1>>(M.data());
}
inline Eigen::Matrix3d unvec(const Eigen::VectorXd& v) {
  return Eigen::Map<const Eigen::Matrix3d>(v.data());
}

/// The full list of test states.
inline std::vector<MaterialState> material_states() {
  using V = Eigen::Vector3d;
  std::vector<MaterialState> states;
  states.push_back({ "rest", Eigen::Matrix3d::Identity() });
  states.push_back({ "pure_rotation", rotated_stretch(V(1, 1, 1), 1) });
  states.push_back({ "moderate", rotated_stretch(V(1.3, 0.9, 0.75), 2) });
  {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int k = 0; k < 9; ++k)
      F.data()[k] += u(rng);
    states.push_back({ "random_general", F });
  }
  states.push_back({ "large_stretch", rotated_stretch(V(2.3, 1.6, 0.5), 4) });
  states.push_back({ "near_inverted", rotated_stretch(V(1.1, 0.8, 1e-3), 5) });
  states.push_back({ "inverted", rotated_stretch(V(1.15, 0.8, -0.3), 6) });
  states.push_back({ "inverted_strongly", rotated_stretch(V(1.4, 0.95, -0.7), 7) });
  states.push_back({ "repeated_top", rotated_stretch(V(1.35, 1.35, 0.8), 8) });
  states.push_back({ "repeated_bottom", rotated_stretch(V(1.3, 0.7, 0.7), 9) });
  states.push_back({ "near_repeated_1e-7", rotated_stretch(V(1.35 + 1e-7, 1.35, 0.8), 10) });
  states.push_back({ "near_repeated_3e-5", rotated_stretch(V(1.35 + 3e-5, 1.35, 0.8), 11) });
  states.push_back({ "uniform_tension", rotated_stretch(V(1.12, 1.12, 1.12), 12) });
  states.push_back({ "uniform_compression", rotated_stretch(V(0.78, 0.78, 0.78), 13) });
  return states;
}

/// States of small strain in tension, where every model's exact tangent is already PSD.
inline std::vector<MaterialState> small_tension_states() {
  using V = Eigen::Vector3d;
  return { { "rest", Eigen::Matrix3d::Identity() }, { "rotation", rotated_stretch(V(1, 1, 1), 21) },
    { "small_tension", rotated_stretch(V(1.02, 1.01, 1.005), 22) },
    { "small_uniaxial", rotated_stretch(V(1.015, 1.0, 1.0), 23) } };
}

} // namespace elastolearn::test
