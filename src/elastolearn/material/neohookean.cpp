#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/neohookean.hpp>

#include <cmath>

namespace elastolearn::material {

NeoHookeanModel::NeoHookeanModel(const Lame& lame, double inversion_threshold)
    : m_lame(lame)
    , m_eps(inversion_threshold)
    , m_log_eps(0) {
  if (!std::isfinite(inversion_threshold) || inversion_threshold <= 0 || inversion_threshold >= 1)
    throw InputError("neohookean.inversion_threshold",
        "must satisfy 0 < threshold < 1, got " + to_text(inversion_threshold));
  m_log_eps = std::log(m_eps);
}

void NeoHookeanModel::extended_log(double x, double& l, double& dl, double& ddl) const {
  if (x >= m_eps) {
    l = std::log(x);
    dl = 1 / x;
    ddl = -dl * dl;
    return;
  }
  const double d = x - m_eps, inv = 1 / m_eps;
  l = m_log_eps + d * inv - 0.5 * d * d * inv * inv;
  dl = inv - d * inv * inv;
  ddl = -inv * inv;
}

double NeoHookeanModel::energy(const Vec3& s) const {
  double L = 0;
  for (int i = 0; i < 3; ++i) {
    double l, dl, ddl;
    extended_log(s[i], l, dl, ddl);
    L += l;
  }
  return 0.5 * m_lame.mu * (s.squaredNorm() - 3) - m_lame.mu * L + 0.5 * m_lame.lambda * L * L;
}

Vec3 NeoHookeanModel::principal_stress(const Vec3& s) const {
  Vec3 dl;
  double L = 0;
  for (int i = 0; i < 3; ++i) {
    double l, ddl;
    extended_log(s[i], l, dl[i], ddl);
    L += l;
  }
  return m_lame.mu * s + (m_lame.lambda * L - m_lame.mu) * dl;
}

Mat3 NeoHookeanModel::principal_stress_derivative(const Vec3& s) const {
  Vec3 dl, ddl;
  double L = 0;
  for (int i = 0; i < 3; ++i) {
    double l;
    extended_log(s[i], l, dl[i], ddl[i]);
    L += l;
  }
  Mat3 d = m_lame.lambda * dl * dl.transpose();
  for (int i = 0; i < 3; ++i)
    d(i, i) += m_lame.mu + (m_lame.lambda * L - m_lame.mu) * ddl[i];
  return d;
}

std::unique_ptr<ElasticModel> NeoHookeanModel::clone() const {
  return std::make_unique<NeoHookeanModel>(*this);
}

} // namespace elastolearn::material
