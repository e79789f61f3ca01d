#pragma once
/// \file Rayleigh damping f_d = −(α₀ M + α₁ K(x)) v (paper 000 §4.1), per element, so that the
/// coefficients may depend on the element's largest principal stretch (the "Bar Damping" cases).
#include <elastolearn/core/types.hpp>

#include <array>
#include <memory>
#include <string>
#include <string_view>

namespace elastolearn::material {

struct RayleighCoefficients {
  double alpha0 = 0; ///< mass-proportional coefficient [1/s]
  double alpha1 = 0; ///< stiffness-proportional coefficient [s]
};

/// Which stiffness K(x) the α₁ term scales (docs/materials.md, "Damping"):
/// - FlipFree: the exact tangent of the element's stress at x without its flip eigenvalues
///   (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ), which leaves the rigid rotation of a stressed element undamped, taken
///   at its dissipative part by the simulator (fem::ElasticForce: the symmetric part of its
///   stretch block and its twists clamped at zero) so that the damping dissipates for every
///   material; unchanged for monotone materials, whose tangent is PSD. elastolearn's
///   default. material::damping_tangent returns it unprojected (linear in the stress), as the
///   learning's correction forces use it.
/// - Exact: the full exact tangent stiffness K(x) = −∂f/∂x at the end-of-step state,
///   unprojected: the standard Rayleigh damping of Vega FEM, SOFA and Drake.
enum class DampingTangent { FlipFree, Exact };

/// Every damping tangent, in table order.
inline constexpr std::array<DampingTangent, 2> all_damping_tangents
    = { DampingTangent::FlipFree, DampingTangent::Exact };

/// "flip-free", "exact" (the names of scene files' "damping.tangent").
std::string to_string(DampingTangent tangent);

/// Inverse of to_string. Throws InputError(where, ...) naming the bad string and the valid ones.
DampingTangent damping_tangent_from_string(
    std::string_view name, const std::string& where = "damping.tangent");

/// Rayleigh coefficients of one element as a function of its largest principal stretch, and the
/// stiffness their α₁ scales.
class DampingModel {
  public:
  virtual ~DampingModel() = default;
  virtual std::string name() const = 0;
  virtual RayleighCoefficients coefficients(double max_stretch) const = 0;
  /// True if the coefficients do not depend on the stretch (lets the assembler skip work).
  virtual bool is_constant() const = 0;
  virtual std::unique_ptr<DampingModel> clone() const = 0;

  DampingTangent tangent() const { return m_tangent; }
  void set_tangent(DampingTangent tangent) { m_tangent = tangent; }

  private:
  DampingTangent m_tangent = DampingTangent::FlipFree;
};

/// The stiffness a damping model's α₁ scales; FlipFree without a model (a correction's Δα₁ then
/// acts alone, on the default tangent).
inline DampingTangent damping_tangent_of(const DampingModel* damping) {
  return damping ? damping->tangent() : DampingTangent::FlipFree;
}

} // namespace elastolearn::material
