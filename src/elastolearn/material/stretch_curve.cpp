#include <elastolearn/core/error.hpp>
#include <elastolearn/material/stretch_curve.hpp>

#include <cmath>

namespace elastolearn::material {

StretchPolynomial::StretchPolynomial(std::vector<double> coefficients, const std::string& where)
    : m_c(std::move(coefficients)) {
  if (m_c.empty())
    throw InputError(where, "a polynomial needs at least one coefficient");
  for (std::size_t k = 0; k < m_c.size(); ++k)
    if (!std::isfinite(m_c[k]))
      throw InputError(where, "coefficient " + std::to_string(k) + " is not finite");
}

void StretchPolynomial::evaluate(double stretch, double& value, double& derivative) const {
  const double t = stretch - 1;
  value = 0;
  derivative = 0;
  for (auto c = m_c.rbegin(); c != m_c.rend(); ++c) {
    derivative = derivative * t + value;
    value = value * t + *c;
  }
  if (value < 0)
    value = derivative = 0;
}

void StretchCurve::evaluate(double stretch, double& value, double& derivative) const {
  std::visit([&](const auto& form) { form.evaluate(stretch, value, derivative); }, m_form);
}

double StretchCurve::value(double stretch) const {
  double v, d;
  evaluate(stretch, v, d);
  return v;
}

double StretchCurve::derivative(double stretch) const {
  double v, d;
  evaluate(stretch, v, d);
  return d;
}

double StretchCurve::lower_bound() const {
  if (const auto* spline = std::get_if<CubicSpline>(&m_form))
    return spline->min_value();
  return 0.0;
}

} // namespace elastolearn::material
