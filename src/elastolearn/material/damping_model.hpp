#pragma once
/// \file Rayleigh damping f_d = −(α₀ M + α₁ K(x)) v (paper 000 §4.1), per element, so that the
/// coefficients may depend on the element's largest principal stretch (the "Bar Damping" cases).
#include <elastolearn/core/types.hpp>

#include <memory>
#include <string>

namespace elastolearn::material {

struct RayleighCoefficients {
  double alpha0 = 0; ///< mass-proportional coefficient [1/s]
  double alpha1 = 0; ///< stiffness-proportional coefficient [s]
};

/// Rayleigh coefficients of one element as a function of its largest principal stretch.
class DampingModel {
  public:
  virtual ~DampingModel() = default;
  virtual std::string name() const = 0;
  virtual RayleighCoefficients coefficients(double max_stretch) const = 0;
  /// True if the coefficients do not depend on the stretch (lets the assembler skip work).
  virtual bool is_constant() const = 0;
  virtual std::unique_ptr<DampingModel> clone() const = 0;
};

} // namespace elastolearn::material
