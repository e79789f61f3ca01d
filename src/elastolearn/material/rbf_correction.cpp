#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <algorithm>
#include <array>

namespace elastolearn::material {

namespace {

constexpr FieldErrors rbf_correction_error("rbf_correction");

/// Stable descending order of three values: order[i] = index of the i-th largest.
std::array<int, 3> descending_order(const Vec3& v) {
  std::array<int, 3> order { 0, 1, 2 };
  for (int i = 1; i < 3; ++i)
    for (int j = i; j > 0 && v[order[j]] > v[order[j - 1]]; --j)
      std::swap(order[j], order[j - 1]);
  return order;
}

/// The other two directions of k, larger stretch first (ties: lower index first).
std::array<int, 2> others_descending(const Vec3& s, int k) {
  int a = (k + 1) % 3, b = (k + 2) % 3;
  if (a > b)
    std::swap(a, b);
  if (s[b] > s[a])
    std::swap(a, b);
  return { a, b };
}

} // namespace

std::array<int, 3> stretch_view_indices(const Vec3& s, int k) {
  const auto o = others_descending(s, k);
  return { k, o[0], o[1] };
}

Vec3 stretch_view(const Vec3& s, int k) {
  const auto i = stretch_view_indices(s, k);
  return { s[i[0]], s[i[1]], s[i[2]] };
}

Eigen::Vector4d quadratic_tail_basis(const Vec3& y) {
  const double e = y[0] - 1, s = y[1] + y[2] - 2;
  return { e * e, e * s, s * s, (y[1] - 1) * (y[2] - 1) };
}

Eigen::Vector2d neo_hookean_tail_basis(const Vec3& y, Eigen::Matrix<double, 2, 3>* d_y) {
  constexpr double floor = 1e-3;
  const Vec3 z = y.cwiseMax(floor);
  const double log_j = std::log(z[0] * z[1] * z[2]);
  const Eigen::Vector2d g(z[0] + 1 / z[0] - 2, log_j / z[0] - (z[0] + z[1] + z[2] - 3));
  if (d_y) {
    d_y->row(0) = Eigen::RowVector3d(1 - 1 / (z[0] * z[0]), 0, 0);
    d_y->row(1) = Eigen::RowVector3d(
        (1 - log_j) / (z[0] * z[0]) - 1, 1 / (z[0] * z[1]) - 1, 1 / (z[0] * z[2]) - 1);
    for (int c = 0; c < 3; ++c)
      if (y[c] < floor)
        d_y->col(c).setZero();
  }
  return g;
}

Vec3 energy_kernel_gradient(
    const Vec3& stretches, const Vec3& centre, double epsilon, Mat3* hessian) {
  // ∂φ(‖u − c‖)/∂u = (u − c)/φ with u = P_π σ, so ∂/∂σ[π_j] receives (u_j − c_j)/φ, and
  // ∂²/∂σ[π_j]∂σ[π_l] receives δ_jl/φ − (u_j − c_j)(u_l − c_l)/φ³.
  const double eps2 = epsilon * epsilon;
  Vec3 gradient = Vec3::Zero();
  if (hessian)
    hessian->setZero();
  for (const auto& pi : kStretchPermutations) {
    const Vec3 d(
        stretches[pi[0]] - centre[0], stretches[pi[1]] - centre[1], stretches[pi[2]] - centre[2]);
    const double phi = std::sqrt(d.squaredNorm() + eps2);
    if (phi == 0)
      continue; // ε = 0 at a centre: the subgradient 0
    for (int j = 0; j < 3; ++j)
      gradient[pi[j]] += d[j] / phi;
    if (hessian)
      for (int j = 0; j < 3; ++j)
        for (int l = 0; l < 3; ++l)
          (*hessian)(pi[j], pi[l]) += ((j == l ? 1.0 : 0.0) - d[j] * d[l] / (phi * phi)) / phi;
  }
  return gradient;
}

double energy_kernel(const Vec3& stretches, const Vec3& centre, double epsilon) {
  double sum = 0;
  for (const auto& pi : kStretchPermutations)
    sum += rbf_kernel(
        (Vec3(stretches[pi[0]], stretches[pi[1]], stretches[pi[2]]) - centre).squaredNorm(),
        epsilon);
  return sum;
}

RbfCorrection::RbfCorrection(Parameters p)
    : m_p(std::move(p)) {
  const Eigen::Index m = m_p.centres.rows();
  if (m_p.weights.size() != m)
    rbf_correction_error("weights",
        "has " + std::to_string(m_p.weights.size()) + " entries, one per centre ("
            + std::to_string(m) + ") expected");
  if (m_p.damping_weights.size() != 0 && m_p.damping_weights.size() != m)
    rbf_correction_error("damping_weights",
        "has " + std::to_string(m_p.damping_weights.size())
            + " entries, expected none or one per centre (" + std::to_string(m) + ")");
  const auto finite = [](const char* field, bool ok) {
    if (!ok)
      rbf_correction_error(field, "contains a non-finite value");
  };
  finite("centres", m_p.centres.allFinite());
  finite("weights", m_p.weights.allFinite());
  finite("own_slope", std::isfinite(m_p.own_slope));
  finite("other_slope", std::isfinite(m_p.other_slope));
  finite("constant", std::isfinite(m_p.constant));
  finite("quadratic", m_p.quadratic.allFinite());
  finite("neo_hookean", m_p.neo_hookean.allFinite());
  finite("damping_weights", m_p.damping_weights.allFinite());
  finite("damping_slopes", m_p.damping_slopes.allFinite());
  finite("damping_constant", std::isfinite(m_p.damping_constant));
  finite("mass_damping", std::isfinite(m_p.mass_damping));
  finite("damping_quadratic", m_p.damping_quadratic.allFinite());
  if (std::isnan(m_p.damping_floor) || m_p.damping_floor == std::numeric_limits<double>::infinity())
    rbf_correction_error("damping_floor", "must be a number or −infinity");
  if (!std::isfinite(m_p.epsilon) || m_p.epsilon < 0) {
    rbf_correction_error("epsilon", "must be finite and ≥ 0, got " + to_text(m_p.epsilon));
  }
  m_p.trusted.validate("rbf_correction.trusted_stretches");
  if (!m_p.energy_kernels && m_p.trusted.bounded())
    rbf_correction_error(
        "trusted_stretches", "needs energy kernels (stress kernels have no energy to continue)");
  if (m_p.energy_kernels && !is_energy_quadratic_tail(m_p.quadratic))
    rbf_correction_error("quadratic",
        "is not the gradient of an energy (energy kernels need quadratic[1] = 2 quadratic[2])");
  if (m_p.energy_kernels)
    m_energy_kernels = EnergyKernelCopies(m_p.centres, m_p.weights, m_p.epsilon);
  if (m_p.damping_weights.size() > 0) {
    const Eigen::Index padded = (m + 3) / 4 * 4;
    for (auto* a : { &m_damping_x, &m_damping_y, &m_damping_z, &m_damping_w })
      a->setZero(padded);
    m_damping_x.head(m) = m_p.centres.col(0);
    m_damping_y.head(m) = m_p.centres.col(1);
    m_damping_z.head(m) = m_p.centres.col(2);
    m_damping_w.head(m) = m_p.damping_weights;
  }
  m_ends = clamp_ends(m_p.trusted, [&](const Vec3& s, Mat3* h) { return formula(s, h); });
}

double RbfCorrection::elastic_energy(const Vec3& stretches) const {
  if (!m_p.energy_kernels)
    rbf_correction_error("energy_kernels", "the correction is not an energy (stress kernels)");
  return continued_energy(
      m_p.trusted, m_ends, stretches, [&](const Vec3& s) { return formula_energy(s); },
      [&](const Vec3& s, Mat3* h) { return formula(s, h); });
}

double RbfCorrection::formula_energy(const Vec3& stretches) const {
  const Vec3 e = stretches - Vec3::Ones();
  const double p1 = e.sum(), p2 = e.squaredNorm(), p3 = e.array().cube().sum();
  double psi = 0;
  for (Eigen::Index i = 0; i < m_p.centres.rows(); ++i)
    psi += m_p.weights[i] * energy_kernel(stretches, m_p.centres.row(i).transpose(), m_p.epsilon);
  // N_k = a e_k + b (p₁ − e_k) + c is the gradient of ½(a − b) p₂ + ½ b p₁² + c p₁.
  const double a = m_p.own_slope, b = m_p.other_slope;
  psi += 0.5 * (a - b) * p2 + 0.5 * b * p1 * p1 + m_p.constant * p1;
  // q = α(3, 6, 3, 0) + β(3, 2, 1, −2) + γ(3, 0, 0, 0) ↔ α p₁³ + β p₁ p₂ + γ p₃.
  const Eigen::Vector4d& q = m_p.quadratic;
  const double beta = -0.5 * q[3], alpha = (q[2] - beta) / 3,
               gamma = (q[0] - 3 * alpha - 3 * beta) / 3;
  psi += alpha * p1 * p1 * p1 + beta * p1 * p2 + gamma * p3;
  if (!m_p.neo_hookean.isZero(0)) {
    // g₁ = −∇E_μ, g₂ = ∇E_λ with E_μ = ½(p₂' − 3) − ln J − Σ(σ − 1)² (p₂' = Σσ²) and
    // E_λ = ½ ln²J − ½ p₁² (neo-Hookean minus corotated, per Lamé parameter).
    const Vec3 z = stretches.cwiseMax(1e-3);
    const double log_j = std::log(z.prod());
    const double e_mu = 0.5 * (z.squaredNorm() - 3) - log_j - (z - Vec3::Ones()).squaredNorm();
    const double e_lambda = 0.5 * log_j * log_j - 0.5 * std::pow((z - Vec3::Ones()).sum(), 2);
    psi += -m_p.neo_hookean[0] * e_mu + m_p.neo_hookean[1] * e_lambda;
  }
  return psi;
}

double RbfCorrection::elastic_tail(const Vec3& y, Vec3* d_y) const {
  const double e = y[0] - 1, s = y[1] + y[2] - 2;
  const Eigen::Vector4d& q = m_p.quadratic;
  double h
      = m_p.own_slope * e + m_p.other_slope * s + m_p.constant + q.dot(quadratic_tail_basis(y));
  if (d_y) {
    const double d_other = m_p.other_slope + q[1] * e + 2 * q[2] * s;
    *d_y = Vec3(m_p.own_slope + 2 * q[0] * e + q[1] * s, d_other + q[3] * (y[2] - 1),
        d_other + q[3] * (y[1] - 1));
  }
  if (!m_p.neo_hookean.isZero(0)) {
    Eigen::Matrix<double, 2, 3> d_g;
    h += m_p.neo_hookean.dot(neo_hookean_tail_basis(y, d_y ? &d_g : nullptr));
    if (d_y)
      *d_y += d_g.transpose() * m_p.neo_hookean;
  }
  return h;
}

Vec3 RbfCorrection::elastic_views(const Mat3& y, Mat3* d_y) const {
  // The kernel sums of the three views run together, lane k of each array being view k (lane 3
  // idle): each lane does exactly the operations of one view evaluated alone, in the same order,
  // so the results are unchanged, while the square roots and divisions, the cost of the whole
  // correction (18 % of a learning run's time), run as packed instructions.
  using Lanes = Eigen::Array4d;
  Lanes h, g0, g1, g2;
  for (int k = 0; k < 3; ++k) {
    Vec3 d_tail;
    h[k] = elastic_tail(y.col(k), d_y ? &d_tail : nullptr);
    if (d_y) {
      g0[k] = d_tail[0];
      g1[k] = d_tail[1];
      g2[k] = d_tail[2];
    }
  }
  h[3] = g0[3] = g1[3] = g2[3] = 0;
  const Lanes y0(y(0, 0), y(0, 1), y(0, 2), 1), y1(y(1, 0), y(1, 1), y(1, 2), 1),
      y2(y(2, 0), y(2, 1), y(2, 2), 1);
  const double eps2 = m_p.epsilon * m_p.epsilon;
  const Eigen::Index kernels = m_p.energy_kernels ? 0 : m_p.centres.rows();
  for (Eigen::Index i = 0; i < kernels; ++i) {
    const double w = m_p.weights[i];
    const Lanes d0 = y0 - m_p.centres(i, 0), d1 = y1 - m_p.centres(i, 1),
                d2 = y2 - m_p.centres(i, 2);
    const Lanes phi = (d0 * d0 + d1 * d1 + d2 * d2 + eps2).sqrt();
    h += w * phi;
    if (d_y) {
      Lanes scale = Lanes::Constant(w) / phi;
      if (eps2 == 0) // 0 at a centre (subgradient); Eigen's select would not run packed
        for (int k = 0; k < 3; ++k)
          if (phi[k] == 0)
            scale[k] = 0;
      g0 += scale * d0;
      g1 += scale * d1;
      g2 += scale * d2;
    }
  }
  if (d_y) {
    d_y->row(0) = g0.head<3>().transpose();
    d_y->row(1) = g1.head<3>().transpose();
    d_y->row(2) = g2.head<3>().transpose();
  }
  return h.head<3>();
}

double RbfCorrection::stiffness_damping(const Vec3& stretches) const {
  const Vec3 at = m_p.trusted.formula_stretches(stretches);
  const auto p = descending_order(at);
  const Vec3 s(at[p[0]], at[p[1]], at[p[2]]);
  const Vec3 e = s - Vec3::Ones();
  double alpha
      = m_p.damping_slopes.dot(e) + m_p.damping_constant + m_p.damping_quadratic.dot(e.cwiseAbs2());
  if (m_damping_w.size() > 0) {
    // Four kernels per packed step (the padding has zero weight).
    using Lanes = Eigen::Array4d;
    const double eps2 = m_p.epsilon * m_p.epsilon;
    Lanes sum = Lanes::Zero();
    for (Eigen::Index j = 0; j < m_damping_w.size(); j += 4) {
      const Lanes dx = s[0] - m_damping_x.segment<4>(j), dy = s[1] - m_damping_y.segment<4>(j),
                  dz = s[2] - m_damping_z.segment<4>(j);
      sum += m_damping_w.segment<4>(j) * (dx * dx + dy * dy + dz * dz + eps2).sqrt();
    }
    alpha += sum.sum();
  }
  return std::max(alpha, m_p.damping_floor);
}

Vec3 RbfCorrection::correction(const Vec3& stretches, const Vec3& /*stretch_rates*/) const {
  return elastic_correction(stretches);
}

Vec3 RbfCorrection::correction_with_gradient(const Vec3& stretches, const Vec3& /*stretch_rates*/,
    Mat3& d_stretches, Mat3& d_stretch_rates) const {
  d_stretch_rates.setZero();
  return continued_correction(m_p.trusted, m_ends, stretches, &d_stretches,
      [&](const Vec3& s, Mat3* h) { return formula(s, h); });
}

Vec3 RbfCorrection::formula(const Vec3& stretches, Mat3* d_stretches) const {
  if (d_stretches == nullptr) {
    Mat3 y;
    for (int k = 0; k < 3; ++k)
      y.col(k) = stretch_view(stretches, k);
    const Vec3 n = elastic_views(y, nullptr);
    return m_p.energy_kernels ? Vec3(n + m_energy_kernels.gradient_sum(stretches, nullptr)) : n;
  }
  std::array<std::array<int, 3>, 3> views;
  Mat3 y, d_y;
  for (int k = 0; k < 3; ++k) {
    views[k] = stretch_view_indices(stretches, k);
    y.col(k) = Vec3(stretches[views[k][0]], stretches[views[k][1]], stretches[views[k][2]]);
  }
  Vec3 n = elastic_views(y, &d_y);
  d_stretches->setZero();
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c)
      (*d_stretches)(k, views[k][c]) += d_y(c, k);
  if (m_p.energy_kernels)
    n += m_energy_kernels.gradient_sum(stretches, d_stretches);
  return n;
}

void RbfCorrection::correction_gradient(const Vec3& stretches, const Vec3& stretch_rates,
    Mat3& d_stretches, Mat3& d_stretch_rates) const {
  correction_with_gradient(stretches, stretch_rates, d_stretches, d_stretch_rates);
}

std::unique_ptr<Correction> RbfCorrection::clone() const {
  return std::make_unique<RbfCorrection>(*this);
}

Vec3 RbfCorrection::elastic_correction(const Vec3& stretches) const {
  return continued_correction(m_p.trusted, m_ends, stretches, nullptr,
      [&](const Vec3& s, Mat3* h) { return formula(s, h); });
}

bool RbfCorrection::has_damping() const {
  return m_p.damping_weights.size() > 0 || !m_p.damping_slopes.isZero(0)
      || m_p.damping_constant != 0 || !m_p.damping_quadratic.isZero(0) || m_p.damping_floor > 0
      || m_p.mass_damping != 0;
}

bool RbfCorrection::has_elastic_part() const {
  return !m_p.weights.isZero(0) || m_p.own_slope != 0 || m_p.other_slope != 0 || m_p.constant != 0
      || !m_p.quadratic.isZero(0) || !m_p.neo_hookean.isZero(0);
}

RbfCorrection blend(const RbfCorrection& a, const RbfCorrection* b, double t) {
  RbfCorrection::Parameters p = a.parameters();
  RbfCorrection::Parameters zero;
  zero.centres.resize(0, 3);
  const RbfCorrection::Parameters& q = b ? b->parameters() : zero;
  if (b && q.epsilon != p.epsilon)
    rbf_correction_error("epsilon", "cannot blend corrections with different kernel smoothing");
  if (b && q.energy_kernels != p.energy_kernels)
    rbf_correction_error("energy_kernels", "cannot blend energy kernels with stress kernels");
  const auto damping_weights = [](const RbfCorrection::Parameters& x) {
    return x.damping_weights.size() > 0 ? x.damping_weights : VecX(VecX::Zero(x.centres.rows()));
  };
  const bool damped = p.damping_weights.size() > 0 || q.damping_weights.size() > 0;
  VecX v = (1 - t) * damping_weights(p);
  p.weights *= 1 - t;
  // b's centres join a's; a centre both share (repeated damped updates blend with the same best
  // correction) is kept once with the summed weights, so the centre count does not grow.
  for (Eigen::Index j = 0; j < q.centres.rows(); ++j) {
    Eigen::Index i = 0;
    while (i < p.centres.rows() && p.centres.row(i) != q.centres.row(j))
      ++i;
    if (i == p.centres.rows()) {
      p.centres.conservativeResize(i + 1, 3);
      p.centres.row(i) = q.centres.row(j);
      p.weights.conservativeResize(i + 1);
      p.weights[i] = 0;
      v.conservativeResize(i + 1);
      v[i] = 0;
    }
    p.weights[i] += t * q.weights[j];
    if (q.damping_weights.size() > 0)
      v[i] += t * q.damping_weights[j];
  }
  if (damped)
    p.damping_weights = v;
  p.own_slope = (1 - t) * p.own_slope + t * q.own_slope;
  p.other_slope = (1 - t) * p.other_slope + t * q.other_slope;
  p.constant = (1 - t) * p.constant + t * q.constant;
  p.quadratic = (1 - t) * p.quadratic + t * q.quadratic;
  p.neo_hookean = (1 - t) * p.neo_hookean + t * q.neo_hookean;
  p.damping_slopes = (1 - t) * p.damping_slopes + t * q.damping_slopes;
  p.damping_constant = (1 - t) * p.damping_constant + t * q.damping_constant;
  p.damping_quadratic = (1 - t) * p.damping_quadratic + t * q.damping_quadratic;
  p.mass_damping = (1 - t) * p.mass_damping + t * q.mass_damping;
  return RbfCorrection(std::move(p));
}

RbfCorrection damping_part(const RbfCorrection& c) {
  RbfCorrection::Parameters p = c.parameters();
  p.weights.setZero();
  p.own_slope = p.other_slope = p.constant = 0;
  p.quadratic.setZero();
  p.neo_hookean.setZero();
  return RbfCorrection(std::move(p));
}

} // namespace elastolearn::material
