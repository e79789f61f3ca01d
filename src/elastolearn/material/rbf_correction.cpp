#include <elastolearn/core/error.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <array>
#include <sstream>

namespace elastolearn::material {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw InputError("rbf_correction." + field, what);
}

/// Stable descending order of three values: order[i] = index of the i-th largest.
std::array<int, 3> descending_order(const Vec3& v) {
  std::array<int, 3> order{0, 1, 2};
  for (int i = 1; i < 3; ++i)
    for (int j = i; j > 0 && v[order[j]] > v[order[j - 1]]; --j) std::swap(order[j], order[j - 1]);
  return order;
}

/// The other two directions of k, larger stretch first (ties: lower index first).
std::array<int, 2> others_descending(const Vec3& s, int k) {
  int a = (k + 1) % 3, b = (k + 2) % 3;
  if (a > b) std::swap(a, b);
  if (s[b] > s[a]) std::swap(a, b);
  return {a, b};
}

} // namespace

Vec3 stretch_view(const Vec3& s, int k) {
  const auto o = others_descending(s, k);
  return {s[k], s[o[0]], s[o[1]]};
}

RbfCorrection::RbfCorrection(Parameters p) : m_p(std::move(p)) {
  const Eigen::Index m = m_p.centres.rows();
  if (m_p.weights.size() != m)
    fail("weights", "has " + std::to_string(m_p.weights.size()) + " entries, one per centre (" + std::to_string(m) +
                        ") expected");
  if (m_p.damping_weights.size() != 0 && m_p.damping_weights.size() != m)
    fail("damping_weights", "has " + std::to_string(m_p.damping_weights.size()) +
                                " entries, expected none or one per centre (" + std::to_string(m) + ")");
  const auto finite = [](const char* field, bool ok) {
    if (!ok) fail(field, "contains a non-finite value");
  };
  finite("centres", m_p.centres.allFinite());
  finite("weights", m_p.weights.allFinite());
  finite("own_slope", std::isfinite(m_p.own_slope));
  finite("other_slope", std::isfinite(m_p.other_slope));
  finite("constant", std::isfinite(m_p.constant));
  finite("damping_weights", m_p.damping_weights.allFinite());
  finite("damping_slope", std::isfinite(m_p.damping_slope));
  finite("damping_constant", std::isfinite(m_p.damping_constant));
  finite("damping_tangent", m_p.damping_tangent.allFinite());
  if (std::isnan(m_p.damping_floor) || m_p.damping_floor == std::numeric_limits<double>::infinity())
    fail("damping_floor", "must be a number or −infinity");
  if (!std::isfinite(m_p.epsilon) || m_p.epsilon < 0) {
    std::ostringstream s;
    s << "must be finite and ≥ 0, got " << m_p.epsilon;
    fail("epsilon", s.str());
  }
}

double RbfCorrection::elastic_view(const Vec3& y, Vec3* d_y) const {
  double h = m_p.own_slope * (y[0] - 1) + m_p.other_slope * (y[1] + y[2] - 2) + m_p.constant;
  if (d_y) *d_y = Vec3(m_p.own_slope, m_p.other_slope, m_p.other_slope);
  const double eps2 = m_p.epsilon * m_p.epsilon;
  for (Eigen::Index i = 0; i < m_p.centres.rows(); ++i) {
    const Vec3 d = y - m_p.centres.row(i).transpose();
    const double phi = std::sqrt(d.squaredNorm() + eps2);
    h += m_p.weights[i] * phi;
    if (d_y && phi > 0) *d_y += (m_p.weights[i] / phi) * d; // 0 at a centre when ε = 0 (subgradient)
  }
  return h;
}

double RbfCorrection::damping(const Vec3& stretches, Vec3* d_s) const {
  double alpha = m_p.damping_slope * (stretches.sum() - 3) + m_p.damping_constant;
  if (d_s) d_s->setConstant(m_p.damping_slope);
  if (m_p.damping_weights.size() == 0) {
    if (alpha >= m_p.damping_floor) return alpha;
    if (d_s) d_s->setZero();
    return m_p.damping_floor;
  }
  const auto p = descending_order(stretches);
  const Vec3 s(stretches[p[0]], stretches[p[1]], stretches[p[2]]);
  const double eps2 = m_p.epsilon * m_p.epsilon;
  for (Eigen::Index i = 0; i < m_p.centres.rows(); ++i) {
    const Vec3 d = s - m_p.centres.row(i).transpose();
    const double phi = std::sqrt(d.squaredNorm() + eps2);
    alpha += m_p.damping_weights[i] * phi;
    if (d_s && phi > 0)
      for (int j = 0; j < 3; ++j) (*d_s)[p[j]] += m_p.damping_weights[i] * d[j] / phi;
  }
  if (alpha < m_p.damping_floor) {
    if (d_s) d_s->setZero();
    return m_p.damping_floor;
  }
  return alpha;
}

Vec3 RbfCorrection::correction(const Vec3& stretches, const Vec3& stretch_rates) const {
  Vec3 n = elastic_correction(stretches);
  if (m_p.damping_weights.size() > 0 || m_p.damping_slope != 0 || m_p.damping_constant != 0)
    n += damping(stretches, nullptr) * (m_p.damping_tangent * stretch_rates);
  return n;
}

void RbfCorrection::correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
                                        Mat3& d_stretch_rates) const {
  d_stretches.setZero();
  for (int k = 0; k < 3; ++k) {
    const auto o = others_descending(stretches, k);
    Vec3 d_y;
    elastic_view(Vec3(stretches[k], stretches[o[0]], stretches[o[1]]), &d_y);
    d_stretches(k, k) += d_y[0];
    d_stretches(k, o[0]) += d_y[1];
    d_stretches(k, o[1]) += d_y[2];
  }
  Vec3 d_alpha;
  const double alpha = damping(stretches, &d_alpha);
  const Vec3 rate_stress = m_p.damping_tangent * stretch_rates;
  d_stretches.noalias() += rate_stress * d_alpha.transpose();
  d_stretch_rates = alpha * m_p.damping_tangent;
}

std::unique_ptr<Correction> RbfCorrection::clone() const { return std::make_unique<RbfCorrection>(*this); }

Vec3 RbfCorrection::elastic_correction(const Vec3& stretches) const {
  Vec3 n;
  for (int k = 0; k < 3; ++k) n[k] = elastic_view(stretch_view(stretches, k), nullptr);
  return n;
}

double RbfCorrection::damping_correction(const Vec3& stretches) const { return damping(stretches, nullptr); }

Mat3 rest_principal_tangent(const ElasticModel& model) { return model.principal_stress_derivative(Vec3::Ones()); }

} // namespace elastolearn::material
