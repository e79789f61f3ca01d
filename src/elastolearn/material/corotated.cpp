#include <elastolearn/material/corotated.hpp>

namespace elastolearn::material {

double CorotatedModel::energy(const Vec3& s) const {
  const Vec3 e = s.array() - 1.0;
  const double tr = e.sum();
  return m_lame.mu * e.squaredNorm() + 0.5 * m_lame.lambda * tr * tr;
}

Vec3 CorotatedModel::principal_stress(const Vec3& s) const {
  const Vec3 e = s.array() - 1.0;
  return 2 * m_lame.mu * e + Vec3::Constant(m_lame.lambda * e.sum());
}

Mat3 CorotatedModel::principal_stress_derivative(const Vec3&) const {
  return 2 * m_lame.mu * Mat3::Identity() + Mat3::Constant(m_lame.lambda);
}

std::unique_ptr<ElasticModel> CorotatedModel::clone() const {
  return std::make_unique<CorotatedModel>(*this);
}

} // namespace elastolearn::material
