#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/spline.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::material {

CubicSpline::CubicSpline(std::vector<double> x, std::vector<double> y, std::string where)
    : m_x(std::move(x))
    , m_y(std::move(y)) {
  if (m_x.empty())
    throw InputError(where, "a spline needs at least one knot");
  if (m_x.size() != m_y.size()) {
    throw InputError(where,
        "knot x and y have different lengths (" + std::to_string(m_x.size()) + " vs "
            + std::to_string(m_y.size()) + ")");
  }
  const std::size_t n = m_x.size();
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(m_x[k]) || !std::isfinite(m_y[k]))
      throw InputError(where,
          "knot " + std::to_string(k) + " is not finite (x = " + to_text(m_x[k])
              + ", y = " + to_text(m_y[k]) + ")");
    if (k > 0 && !(m_x[k] > m_x[k - 1]))
      throw InputError(where,
          "knot x must be strictly increasing, but x[" + std::to_string(k) + "] = "
              + to_text(m_x[k]) + " <= x[" + std::to_string(k - 1) + "] = " + to_text(m_x[k - 1]));
  }
  // Fritsch–Carlson tangents.
  m_m.assign(n, 0.0);
  if (n < 3)
    return; // zero end tangents; one interval is a smoothstep between the two values
  std::vector<double> delta(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k)
    delta[k] = (m_y[k + 1] - m_y[k]) / (m_x[k + 1] - m_x[k]);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    m_m[k] = (delta[k - 1] * delta[k] > 0) ? 0.5 * (delta[k - 1] + delta[k]) : 0.0;
  }
  for (std::size_t k = 0; k + 1 < n; ++k) {
    if (delta[k] == 0) {
      m_m[k] = m_m[k + 1] = 0;
      continue;
    }
    const double a = m_m[k] / delta[k], b = m_m[k + 1] / delta[k];
    const double r2 = a * a + b * b;
    if (r2 > 9) {
      const double t = 3 / std::sqrt(r2);
      m_m[k] = t * a * delta[k];
      m_m[k + 1] = t * b * delta[k];
    }
  }
}

void CubicSpline::evaluate(double x, double& value, double& derivative) const {
  if (x <= m_x.front()) {
    value = m_y.front();
    derivative = 0;
    return;
  }
  if (x >= m_x.back()) {
    value = m_y.back();
    derivative = 0;
    return;
  }
  // Interval k with x_k <= x < x_{k+1}.
  const std::size_t k
      = static_cast<std::size_t>(std::upper_bound(m_x.begin(), m_x.end(), x) - m_x.begin()) - 1;
  const double h = m_x[k + 1] - m_x[k];
  const double t = (x - m_x[k]) / h;
  const double t2 = t * t, t3 = t2 * t;
  const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t;
  const double h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
  value = h00 * m_y[k] + h10 * h * m_m[k] + h01 * m_y[k + 1] + h11 * h * m_m[k + 1];
  const double d00 = 6 * t2 - 6 * t, d10 = 3 * t2 - 4 * t + 1;
  const double d01 = -6 * t2 + 6 * t, d11 = 3 * t2 - 2 * t;
  derivative = (d00 * m_y[k] + d01 * m_y[k + 1]) / h + d10 * m_m[k] + d11 * m_m[k + 1];
}

double CubicSpline::value(double x) const {
  double v, d;
  evaluate(x, v, d);
  return v;
}

double CubicSpline::derivative(double x) const {
  double v, d;
  evaluate(x, v, d);
  return d;
}

double CubicSpline::min_value() const {
  return *std::min_element(m_y.begin(), m_y.end());
}
double CubicSpline::max_value() const {
  return *std::max_element(m_y.begin(), m_y.end());
}

} // namespace elastolearn::material
