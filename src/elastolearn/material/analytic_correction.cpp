#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/analytic_correction.hpp>

#include <cmath>

namespace elastolearn::material {

namespace {
constexpr FieldErrors analytic_correction_error("analytic_correction");
} // namespace

AnalyticCorrection::AnalyticCorrection(const Parameters& p)
    : m_p(p) {
  const double values[3] = { p.a, p.b, p.c };
  const char* names[3] = { "a", "b", "c" };
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(values[k]))
      analytic_correction_error(names[k], "must be finite, got " + to_text(values[k]));
  }
}

Vec3 AnalyticCorrection::correction(const Vec3& s, const Vec3& r) const {
  const Vec3 e = s.array() - 1.0;
  const double g = 1 + m_p.c * e.squaredNorm();
  return m_p.a * e.array().cube().matrix() + m_p.b * g * r;
}

void AnalyticCorrection::correction_gradient(
    const Vec3& s, const Vec3& r, Mat3& d_stretches, Mat3& d_stretch_rates) const {
  const Vec3 e = s.array() - 1.0;
  const double g = 1 + m_p.c * e.squaredNorm();
  d_stretches = (2 * m_p.b * m_p.c) * r * e.transpose();
  d_stretches.diagonal() += 3 * m_p.a * e.array().square().matrix();
  d_stretch_rates = m_p.b * g * Mat3::Identity();
}

std::unique_ptr<Correction> AnalyticCorrection::clone() const {
  return std::make_unique<AnalyticCorrection>(*this);
}

} // namespace elastolearn::material
