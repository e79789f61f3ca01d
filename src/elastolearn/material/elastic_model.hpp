#pragma once
/// \file Isotropic hyperelastic models written in principal stretches (paper 000 §4.1).
#include <elastolearn/core/types.hpp>

#include <memory>
#include <string>

namespace elastolearn::material {

/// Lamé parameters [Pa].
struct Lame {
  double mu = 0;
  double lambda = 0;
  /// From Young's modulus E [Pa] and Poisson ratio ν (−1 < ν < 0.5); throws InputError otherwise.
  static Lame from_young_poisson(double young, double poisson);
};

/// An isotropic elastic model as a function of the principal stretches σ = (σ1, σ2, σ3),
/// sorted descending; σ3 may be negative for an inverted element (inversion-safe SVD).
/// Energy density Ψ(σ) [J/m³], principal (diagonal) first Piola stress P̂ = ∂Ψ/∂σ [Pa],
/// and its 3×3 derivative ∂P̂/∂σ (symmetric). All are symmetric functions of σ.
/// Implementations must be thread-safe (const, no mutable state) and allocation-free.
class ElasticModel {
  public:
  virtual ~ElasticModel() = default;
  /// Short identifier used in JSON and the CLI ("corotated", "stvk", "neohookean", ...).
  virtual std::string name() const = 0;
  virtual double energy(const Vec3& stretches) const = 0;
  virtual Vec3 principal_stress(const Vec3& stretches) const = 0;
  virtual Mat3 principal_stress_derivative(const Vec3& stretches) const = 0;
  virtual std::unique_ptr<ElasticModel> clone() const = 0;
};

} // namespace elastolearn::material
