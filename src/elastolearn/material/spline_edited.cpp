#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/spline_edited.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastolearn::material {

std::string to_string(SplineEditRegion region) {
  return region == SplineEditRegion::Tension ? "tension" : "compression";
}

SplineEditRegion spline_edit_region_from_string(std::string_view name, const std::string& where) {
  if (name == "tension")
    return SplineEditRegion::Tension;
  if (name == "compression")
    return SplineEditRegion::Compression;
  throw InputError(where,
      "unknown spline edit region '" + std::string(name) + "' (valid: tension, compression)");
}

SplineEditedModel::SplineEditedModel(ElasticModelType base, const Lame& lame,
    SplineEditRegion region, CubicSpline spline, const std::string& where)
    : m_base_type(base)
    , m_lame(lame)
    , m_region(region)
    , m_spline(std::move(spline)) {
  if (base != ElasticModelType::Corotated && base != ElasticModelType::NeoHookean) {
    throw InputError(where + ".base",
        "a spline edit needs base 'corotated' or 'neohookean', got '" + to_string(base) + "'");
  }
  m_base = make_elastic_model(base, lame);
  const auto& x = m_spline.knots_x();
  const auto& y = m_spline.knots_y();
  const bool tension = region == SplineEditRegion::Tension;
  const std::size_t near = tension ? 0 : x.size() - 1; // knot nearest the rest stretch
  if (tension ? !(x.front() >= 1) : !(x.back() <= 1))
    throw InputError(where + ".spline",
        "knots of a " + to_string(region) + " edit must satisfy x " + (tension ? ">=" : "<=")
            + " 1, got x = " + to_text_exact(x[near]));
  if (std::abs(y[near] - 1) > 1e-12)
    throw InputError(where + ".spline",
        "the knot nearest the rest stretch (x = " + to_text_exact(x[near])
            + ") must have value 1, got " + to_text_exact(y[near]));
  if (!(m_spline.min_value() > 0))
    throw InputError(where + ".spline",
        "spline values must be positive, got " + to_text_exact(m_spline.min_value()));
}

double SplineEditedModel::f_prime(double x) const {
  return m_base_type == ElasticModelType::Corotated ? 2 * m_lame.mu * (x - 1) : m_lame.mu * x;
}

double SplineEditedModel::f_second(double) const {
  return m_base_type == ElasticModelType::Corotated ? 2 * m_lame.mu : m_lame.mu;
}

double SplineEditedModel::integrate(double a, double b) const {
  // Pieces on which s is one cubic: (−∞, x₀], [x₀, x₁], ..., [x_{n−1}, ∞).
  static constexpr double gl_nodes[3] = { -0.7745966692414834, 0.0, 0.7745966692414834 };
  static constexpr double gl_weights[3] = { 5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0 };
  const auto& x = m_spline.knots_x();
  const std::size_t n = x.size();
  const double inf = std::numeric_limits<double>::infinity();
  double sum = 0;
  for (std::size_t k = 0; k <= n; ++k) {
    const double lo = std::max(a, k == 0 ? -inf : x[k - 1]);
    const double hi = std::min(b, k == n ? inf : x[k]);
    if (!(hi > lo))
      continue;
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    for (int q = 0; q < 3; ++q) {
      const double t = mid + half * gl_nodes[q];
      sum += gl_weights[q] * half * (m_spline.value(t) - 1) * f_prime(t);
    }
  }
  return sum;
}

double SplineEditedModel::edit_energy(double x) const {
  return x >= 1 ? integrate(1, x) : -integrate(x, 1);
}

double SplineEditedModel::energy(const Vec3& s) const {
  return m_base->energy(s) + edit_energy(s[0]) + edit_energy(s[1]) + edit_energy(s[2]);
}

Vec3 SplineEditedModel::principal_stress(const Vec3& s) const {
  Vec3 p = m_base->principal_stress(s);
  for (int i = 0; i < 3; ++i)
    p[i] += (m_spline.value(s[i]) - 1) * f_prime(s[i]);
  return p;
}

Mat3 SplineEditedModel::principal_stress_derivative(const Vec3& s) const {
  Mat3 d = m_base->principal_stress_derivative(s);
  for (int i = 0; i < 3; ++i) {
    double v, dv;
    m_spline.evaluate(s[i], v, dv);
    d(i, i) += dv * f_prime(s[i]) + (v - 1) * f_second(s[i]);
  }
  return d;
}

std::unique_ptr<ElasticModel> SplineEditedModel::clone() const {
  return std::make_unique<SplineEditedModel>(m_base_type, m_lame, m_region, m_spline);
}

} // namespace elastolearn::material
