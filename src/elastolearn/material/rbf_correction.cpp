#include <elastolearn/core/error.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <array>
#include <cmath>
#include <sstream>

namespace elastolearn::material {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw InputError("rbf_correction." + field, what);
}

/// Stable descending order of three values: order[i] = index of the i-th largest.
std::array<int, 3> descending_order(const Vec3& v) {
  std::array<int, 3> order { 0, 1, 2 };
  // Three-element insertion sort (stable: equal values keep their input order).
  for (int i = 1; i < 3; ++i) {
    for (int j = i; j > 0 && v[order[j]] > v[order[j - 1]]; --j)
      std::swap(order[j], order[j - 1]);
  }
  return order;
}

} // namespace

RbfCorrection::RbfCorrection(Parameters p)
    : m_p(std::move(p)) {
  const Eigen::Index m = m_p.centres.rows();
  if (m_p.weights.rows() != m) {
    fail("weights",
        "has " + std::to_string(m_p.weights.rows()) + " rows, one per centre (" + std::to_string(m)
            + ") expected");
  }
  if (m_p.damping_weights.size() != 0 && m_p.damping_weights.size() != m) {
    fail("damping_weights",
        "has " + std::to_string(m_p.damping_weights.size())
            + " entries, expected none or one per centre (" + std::to_string(m) + ")");
  }
  const auto finite = [](const char* field, bool ok) {
    if (!ok)
      fail(field, "contains a non-finite value");
  };
  finite("centres", m_p.centres.allFinite());
  finite("weights", m_p.weights.allFinite());
  finite("linear", m_p.linear.allFinite());
  finite("constant", m_p.constant.allFinite());
  finite("damping_weights", m_p.damping_weights.allFinite());
  finite("damping_linear", m_p.damping_linear.allFinite());
  finite("damping_constant", std::isfinite(m_p.damping_constant));
  finite("damping_tangent", m_p.damping_tangent.allFinite());
  if (!std::isfinite(m_p.epsilon) || m_p.epsilon < 0) {
    std::ostringstream s;
    s << "must be finite and ≥ 0, got " << m_p.epsilon;
    fail("epsilon", s.str());
  }
}

Vec3 RbfCorrection::evaluate_sorted(const Vec3& s, const Vec3& f, Mat3* d_s, Mat3* d_f) const {
  const Vec3 e = s.array() - 1.0;
  Vec3 elastic = m_p.linear * e + m_p.constant;
  double alpha = m_p.damping_linear.dot(e) + m_p.damping_constant;
  Mat3 d_elastic = m_p.linear;
  Vec3 d_alpha = m_p.damping_linear;
  const bool damping = m_p.damping_weights.size() > 0;
  const bool gradient = d_s != nullptr;
  const double eps2 = m_p.epsilon * m_p.epsilon;
  for (Eigen::Index i = 0; i < m_p.centres.rows(); ++i) {
    const Vec3 d = s - m_p.centres.row(i).transpose();
    const double phi = std::sqrt(d.squaredNorm() + eps2);
    elastic.noalias() += phi * m_p.weights.row(i).transpose();
    if (damping)
      alpha += phi * m_p.damping_weights[i];
    if (gradient && phi > 0) {
      const Vec3 d_phi = d / phi; // ∂φ/∂σ; 0 at the centre when ε = 0 (subgradient)
      d_elastic.noalias() += m_p.weights.row(i).transpose() * d_phi.transpose();
      if (damping)
        d_alpha += m_p.damping_weights[i] * d_phi;
    }
  }
  const Vec3 damping_stress_per_alpha = m_p.damping_tangent * f;
  if (gradient) {
    *d_s = d_elastic + damping_stress_per_alpha * d_alpha.transpose();
    *d_f = alpha * m_p.damping_tangent;
  }
  return elastic + alpha * damping_stress_per_alpha;
}

Vec3 RbfCorrection::correction(const Vec3& stretches, const Vec3& stretch_rates) const {
  const std::array<int, 3> p = descending_order(stretches);
  const Vec3 s(stretches[p[0]], stretches[p[1]], stretches[p[2]]);
  const Vec3 f(stretch_rates[p[0]], stretch_rates[p[1]], stretch_rates[p[2]]);
  const Vec3 n_sorted = evaluate_sorted(s, f, nullptr, nullptr);
  Vec3 n;
  for (int i = 0; i < 3; ++i)
    n[p[i]] = n_sorted[i];
  return n;
}

void RbfCorrection::correction_gradient(const Vec3& stretches, const Vec3& stretch_rates,
    Mat3& d_stretches, Mat3& d_stretch_rates) const {
  const std::array<int, 3> p = descending_order(stretches);
  const Vec3 s(stretches[p[0]], stretches[p[1]], stretches[p[2]]);
  const Vec3 f(stretch_rates[p[0]], stretch_rates[p[1]], stretch_rates[p[2]]);
  Mat3 g_s, g_f;
  evaluate_sorted(s, f, &g_s, &g_f);
  // N[p[i]] = N_sorted[i](σ[p[0]], σ[p[1]], σ[p[2]]): ∂N[p[i]]/∂σ[p[j]] = ∂N_sorted[i]/∂s[j].
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      d_stretches(p[i], p[j]) = g_s(i, j);
      d_stretch_rates(p[i], p[j]) = g_f(i, j);
    }
  }
}

std::unique_ptr<Correction> RbfCorrection::clone() const {
  return std::make_unique<RbfCorrection>(*this);
}

Vec3 RbfCorrection::elastic_correction(const Vec3& stretches) const {
  return correction(stretches, Vec3::Zero());
}

double RbfCorrection::damping_correction(const Vec3& stretches) const {
  const std::array<int, 3> p = descending_order(stretches);
  const Vec3 e = Vec3(stretches[p[0]], stretches[p[1]], stretches[p[2]]).array() - 1.0;
  double alpha = m_p.damping_linear.dot(e) + m_p.damping_constant;
  if (m_p.damping_weights.size() == 0)
    return alpha;
  for (Eigen::Index i = 0; i < m_p.centres.rows(); ++i) {
    const Vec3 d = (e.array() + 1.0).matrix() - m_p.centres.row(i).transpose();
    alpha += m_p.damping_weights[i] * rbf_kernel(d.squaredNorm(), m_p.epsilon);
  }
  return alpha;
}

Mat3 rest_principal_tangent(const ElasticModel& model) {
  return model.principal_stress_derivative(Vec3::Ones());
}

} // namespace elastolearn::material
