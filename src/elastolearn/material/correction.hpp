#pragma once
/// \file The material correction hook N(F̂, Ḟ̂) of paper 000, Eq. (1):
///   P = U (P̂(F̂) + N(F̂, Ḟ̂)) Vᵀ,
/// with F̂ the principal stretches (sorted descending) and Ḟ̂ = diag(Uᵀ Ḟ V) the stretch rates.
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/types.hpp>

#include <algorithm>
#include <memory>
#include <string>

namespace elastolearn::material {

/// A correction to the principal stress: 6 inputs (stretches, stretch rates), 3 outputs [Pa].
/// Implementations must be thread-safe and allocation-free in `correction`, `correction_gradient`
/// and `correction_with_gradient`.
class Correction {
  public:
  virtual ~Correction() = default;
  virtual std::string name() const = 0;
  /// N(F̂, Ḟ̂).
  virtual Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const = 0;
  /// ∂N/∂F̂ (3×3, row = output) and ∂N/∂Ḟ̂ (3×3).
  virtual void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates,
      Mat3& d_stretches, Mat3& d_stretch_rates) const = 0;
  /// N and both gradients in one call, what the element loops need; the default calls the two
  /// above, an implementation may share their work (the RBF evaluates each kernel once).
  virtual Vec3 correction_with_gradient(const Vec3& stretches, const Vec3& stretch_rates,
      Mat3& d_stretches, Mat3& d_stretch_rates) const {
    correction_gradient(stretches, stretch_rates, d_stretches, d_stretch_rates);
    return correction(stretches, stretch_rates);
  }
  /// Whether N depends on the stretch rates at all (false lets the element loops reuse N(F̂, Ḟ̂)
  /// as the elastic part N(F̂, 0)). Default: true.
  virtual bool depends_on_rates() const { return true; }
  /// Δα₁(F̂) [s]: a correction of the element's Rayleigh stiffness-damping coefficient (paper
  /// Eq. 13). The element's damping force becomes −α₁ K_e v_e − Δα₁ K_e^nom v_e with K_e the
  /// corrected and K_e^nom the *nominal* model's stiffness (fem::ElasticForce), so that the
  /// learned damping is linear in Δα₁ and damps every deformation mode, not only the stretch
  /// rates. Default: none.
  virtual double stiffness_damping(const Vec3& /*stretches*/) const { return 0; }
  /// Δα₀ [1/s]: a constant change of the Rayleigh mass-damping coefficient. The element's mass
  /// damping becomes −(α₀ + Δα₀)⁺ M_e v_e. A nominal whose α₀ was fitted without the correction
  /// may have absorbed an elastic misfit into α₀; learning Δα₀ with the correction lets it go
  /// back (docs/learning_recipe.md, "The nominal's damping, learned with the correction").
  /// Default: none.
  virtual double mass_damping() const { return 0; }
  /// Whether the elastic part N(F̂, 0) is the gradient of an energy ΔΨ(F̂) (elastic_energy): the
  /// corrected material is then hyperelastic, and fem::ElasticForce::elastic_energy counts it.
  /// Default: no.
  virtual bool has_elastic_energy() const { return false; }
  /// ΔΨ(F̂) [J/m³] up to a constant, with ∇ΔΨ = N(F̂, 0). Only where has_elastic_energy();
  /// throws InputError otherwise.
  virtual double elastic_energy(const Vec3& /*stretches*/) const {
    throw InputError(name(), "the correction is not the gradient of an energy");
  }
  virtual std::unique_ptr<Correction> clone() const = 0;
};

/// An element's stiffness-damping coefficient with a correction: α₁ + Δα₁(F̂), kept ≥ 0 (a
/// negative total would feed energy in); α₁ itself without a correction. The one rule that
/// fem::ElasticForce and the learning's correction forces share.
inline double corrected_stiffness_damping(
    double alpha1, const Correction* correction, const Vec3& stretches) {
  return correction ? std::max(0.0, alpha1 + correction->stiffness_damping(stretches)) : alpha1;
}

/// An element's mass-damping coefficient with a correction: α₀ + Δα₀, kept ≥ 0 as α₁ + Δα₁ is.
inline double corrected_mass_damping(double alpha0, const Correction* correction) {
  return correction ? std::max(0.0, alpha0 + correction->mass_damping()) : alpha0;
}

} // namespace elastolearn::material
