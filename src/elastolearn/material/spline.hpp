#pragma once
/// \file A C¹ monotone cubic spline (Fritsch–Carlson Hermite) used to edit stress–stretch curves
/// (spline-edited materials, after Xu et al. 2015) and to make Rayleigh coefficients depend on the
/// largest principal stretch (paper 000 §7, "Bar Damping").
#include <string>
#include <vector>

namespace elastolearn::material {

/// Piecewise cubic Hermite interpolant through knots (x_k, y_k), k = 0..n−1.
///
/// - Interior tangents by Fritsch–Carlson (1980): secant average, zero at local extrema, limited
///   so that the interpolant is monotone on every interval where the data are (no overshoot:
///   the spline stays within [min y, max y]).
/// - End tangents are zero, and outside [x_0, x_{n−1}] the spline is constant (y_0 resp. y_{n−1}).
///   Together this makes the spline C¹ on the whole real line (value and derivative continuous).
/// - With a single knot the spline is the constant y_0.
/// Evaluation is allocation-free and thread-safe (binary search over the knots).
class CubicSpline {
  public:
  /// Builds the spline. `where` names the input (JSON field, CLI option) in error messages.
  /// Throws InputError if there are no knots, the sizes differ, a value is not finite, or the
  /// x_k are not strictly increasing.
  CubicSpline(std::vector<double> x, std::vector<double> y, std::string where = "spline");

  /// s(x); constant extrapolation outside the knot range.
  double value(double x) const;
  /// s′(x); zero outside the knot range.
  double derivative(double x) const;
  /// s(x) and s′(x) together.
  void evaluate(double x, double& value, double& derivative) const;

  const std::vector<double>& knots_x() const { return m_x; }
  const std::vector<double>& knots_y() const { return m_y; }
  /// Hermite tangents s′(x_k) at the knots.
  const std::vector<double>& tangents() const { return m_m; }
  /// Smallest and largest knot value (bounds of the spline, by monotonicity of each piece).
  double min_value() const;
  double max_value() const;

  private:
  std::vector<double> m_x, m_y, m_m;
};

} // namespace elastolearn::material
