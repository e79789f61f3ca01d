#pragma once
/// \file A coefficient as a function of an element's largest principal stretch σ₁: a monotone
/// cubic spline through edited knots, or a polynomial in σ₁ − 1. Paper 000 §7.2.2 makes its bar
/// truths' α₁ "a polynomial function of principal stretch".
#include <elastolearn/material/spline.hpp>

#include <string>
#include <variant>
#include <vector>

namespace elastolearn::material {

/// p(σ) = max(0, Σₖ cₖ (σ − 1)ᵏ): a polynomial in the departure from rest, clamped at zero so
/// that a damping coefficient it gives never turns negative (damping that would add energy).
class StretchPolynomial {
  public:
  /// Throws InputError(where, ...) if there is no coefficient or one is not finite.
  explicit StretchPolynomial(
      std::vector<double> coefficients, const std::string& where = "polynomial");
  /// p(σ) and p′(σ) (zero where the clamp is active). Horner's scheme; allocation-free.
  void evaluate(double stretch, double& value, double& derivative) const;
  const std::vector<double>& coefficients() const { return m_c; }

  private:
  std::vector<double> m_c;
};

/// Either of the two forms, evaluated alike. Implicit from either form, so a spline is a curve.
class StretchCurve {
  public:
  StretchCurve(CubicSpline spline)
      : m_form(std::move(spline)) { }
  StretchCurve(StretchPolynomial polynomial)
      : m_form(std::move(polynomial)) { }
  static StretchCurve constant(double value) { return CubicSpline({ 1.0 }, { value }); }

  double value(double stretch) const;
  double derivative(double stretch) const;
  void evaluate(double stretch, double& value, double& derivative) const;
  /// A lower bound of the values: a spline's smallest knot value (a monotone spline stays
  /// within its knots), 0 for a polynomial (clamped).
  double lower_bound() const;

  private:
  std::variant<CubicSpline, StretchPolynomial> m_form;
};

} // namespace elastolearn::material
