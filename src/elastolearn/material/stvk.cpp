#include <elastolearn/material/stvk.hpp>

namespace elastolearn::material {

double StVKModel::energy(const Vec3& s) const {
  const Vec3 E = 0.5 * (s.array().square() - 1.0);
  const double tr = E.sum();
  return m_lame.mu * E.squaredNorm() + 0.5 * m_lame.lambda * tr * tr;
}

Vec3 StVKModel::principal_stress(const Vec3& s) const {
  const double tr = 0.5 * (s.squaredNorm() - 3.0);
  Vec3 p;
  for (int i = 0; i < 3; ++i)
    p[i] = s[i] * (m_lame.mu * (s[i] * s[i] - 1) + m_lame.lambda * tr);
  return p;
}

Mat3 StVKModel::principal_stress_derivative(const Vec3& s) const {
  const double tr = 0.5 * (s.squaredNorm() - 3.0);
  Mat3 d = m_lame.lambda * s * s.transpose();
  for (int i = 0; i < 3; ++i)
    d(i, i) += m_lame.mu * (3 * s[i] * s[i] - 1) + m_lame.lambda * tr;
  return d;
}

std::unique_ptr<ElasticModel> StVKModel::clone() const {
  return std::make_unique<StVKModel>(*this);
}

} // namespace elastolearn::material
