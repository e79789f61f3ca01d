#pragma once
/// \file Reference 1-D spring force laws: the physics the learned springs are trained on and
/// compared with. Sign convention: `force(e, v)` is the force on the moving particle of the 1-D
/// training scenario (paper 004 §2) along +e, so a stretched spring (e > 0) pulls back (force < 0).
#include <string>
#include <string_view>

namespace elastolearn::springs {

/// Kind of elastic term. One name table (`to_string` / `spring_law_kind_from_string`) serves
/// the CLI and the JSON files.
enum class SpringLawKind {
  linear, ///< f = −k e − c v (paper 004 §2)
  cubic, ///< hardening: f = −k e − k3 e³ − c v
  bilinear, ///< tension/compression asymmetry: f = −(e > 0 ? k : k_compression) e − c v
};

/// "linear", "cubic", "bilinear".
std::string_view to_string(SpringLawKind kind);
/// Inverse of to_string; throws InputError(where, ...) listing the valid names.
SpringLawKind spring_law_kind_from_string(const std::string& name, const std::string& where);

/// A 1-D spring force law f(e, v) with elongation e [m] and elongation rate v [m/s].
struct SpringLaw {
  SpringLawKind kind = SpringLawKind::linear;
  double k = 100.0; ///< stiffness [N/m] (tension stiffness for bilinear)
  double c = 0.0; ///< viscous damping [N s/m]
  double k3 = 0.0; ///< cubic coefficient [N/m³] (cubic only)
  double k_compression = 0.0; ///< stiffness for e < 0 [N/m] (bilinear only)

  /// Throws InputError("spring law", ...) for negative or non-finite coefficients.
  void validate() const;
  /// Force on the particle along +e [N].
  double force(double e, double v) const;
  /// ∂f/∂e [N/m] (right derivative at the bilinear kink).
  double force_derivative_e(double e, double v) const;
  /// ∂f/∂v [N s/m].
  double force_derivative_v(double e, double v) const;
};

} // namespace elastolearn::springs
