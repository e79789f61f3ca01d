#pragma once
/// \file The activation functions of the network correction (material/nn_correction.hpp) and of
/// its training (learn/mlp_training.hpp, learn/energy_mlp_training.hpp): one definition of f, f'
/// and f'' that inference and training share. Paper 000 §6.2 / Fig. 6 compares ELU, ReLU and
/// sigmoid; softplus, tanh and squareplus are the smooth (C∞) choices of the energy network, whose
/// stress is f' and whose tangent is f'' (docs/learning.md, "Energy network").
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

namespace elastolearn::material {

enum class Activation {
  Elu, ///< z (z > 0), eᶻ − 1 (z ≤ 0), α = 1: C¹, f'' jumps from 1 to 0 at z = 0
  Relu, ///< max(z, 0): C⁰, f'' = 0
  Sigmoid, ///< 1/(1 + e⁻ᶻ): C∞, bounded
  Softplus, ///< ln(1 + eᶻ): C∞, f' the sigmoid, f'' = f'(1 − f')
  Tanh, ///< tanh z: C∞, bounded
  /// (z + √(z² + 4))/2 (Barron 2021, "squareplus"): C∞ and softplus-like (→ max(z, 0) for
  /// large |z|, growing linearly), but algebraic: one square root and one division, no
  /// exponential, so it vectorises; f' = (1 + z/q)/2, f'' = 2/q³ with q = √(z² + 4).
  Squareplus,
};

/// "elu", "relu", "sigmoid", "softplus", "tanh", "squareplus".
std::string to_string(Activation a);
/// The inverse of to_string; nullopt for another name.
std::optional<Activation> activation_from_string(const std::string& name);

/// f(z), f'(z) and f''(z) of one activation at one point.
struct ActivationValues {
  double f, d1, d2;
};

/// f, f', f'' at z (f'' at a kink: the right-hand value, 0 for ELU and ReLU at z = 0). One
/// exponential (ELU, sigmoid, softplus, tanh) plus a log1p for softplus's value; a square root
/// and a division for squareplus.
inline ActivationValues activation_values(Activation a, double z) {
  switch (a) {
  case Activation::Elu: {
    if (z > 0)
      return { z, 1, 0 };
    const double e = std::exp(z);
    return { std::expm1(z), e, e };
  }
  case Activation::Relu:
    return { z > 0 ? z : 0, z > 0 ? 1.0 : 0.0, 0 };
  case Activation::Sigmoid: {
    const double s = 1 / (1 + std::exp(-z)), d = s * (1 - s);
    return { s, d, d * (1 - 2 * s) };
  }
  case Activation::Softplus: {
    // ln(1 + eᶻ) = max(z, 0) + ln(1 + e^−|z|): no overflow for large |z|.
    const double s = 1 / (1 + std::exp(-z));
    return { std::max(z, 0.0) + std::log1p(std::exp(-std::abs(z))), s, s * (1 - s) };
  }
  case Activation::Tanh: {
    const double t = std::tanh(z), d = 1 - t * t;
    return { t, d, -2 * t * d };
  }
  case Activation::Squareplus: {
    const double q = std::sqrt(z * z + 4), r = 1 / q;
    return { 0.5 * (z + q), 0.5 * (1 + z * r), 2 * r * r * r };
  }
  }
  return { 0, 0, 0 };
}

} // namespace elastolearn::material
