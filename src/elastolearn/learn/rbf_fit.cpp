#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/rbf_fit.hpp>

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors rbf_fit_error("rbf_fit");

constexpr Eigen::Index k_chunk = 2048;

/// −P K P with K_ij = kernel(i, j) (m × m) and P = I − 11ᵀ/m, symmetrised and scaled to unit
/// trace; zero if its trace is not positive (one centre, or all centres equal).
template <typename Kernel> MatX unit_trace_seminorm(int m, const Kernel& kernel) {
  MatX k(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      k(i, j) = kernel(i, j);
  const MatX p = MatX::Identity(m, m) - MatX::Constant(m, m, 1.0 / m);
  MatX r = -p * k * p;
  r = 0.5 * (r + r.transpose()).eval();
  const double trace = r.trace();
  return trace > 0 ? MatX(r / trace) : MatX(MatX::Zero(m, m));
}

} // namespace

void RbfFitOptions::validate() const {
  if (continuation == material::Continuation::edge_hessian)
    rbf_fit_error("continuation",
        "learning continues with bounded_softening, smooth_expansion or smooth_clamp");
  if (!std::isfinite(epsilon) || epsilon < 0)
    rbf_fit_error("epsilon", "must be finite and ≥ 0, got " + to_text(epsilon));
  if (!std::isfinite(regularization) || regularization < 0)
    rbf_fit_error("regularization", "must be finite and ≥ 0, got " + to_text(regularization));
  if (!std::isfinite(damping_regularization) || damping_regularization < 0)
    rbf_fit_error(
        "damping_regularization", "must be finite and ≥ 0, got " + to_text(damping_regularization));
  if (!std::isfinite(smoothness) || smoothness < 0)
    rbf_fit_error("smoothness", "must be finite and ≥ 0, got " + to_text(smoothness));
  if (std::isnan(damping_floor) || damping_floor > 0)
    rbf_fit_error("damping_floor", "must be ≤ 0 (or −infinity), got " + to_text(damping_floor));
  if (damping_quadratic_tail && !damping_polynomial)
    rbf_fit_error("damping_quadratic_tail", "needs damping_polynomial (the linear tail)");
}

RbfDesign::RbfDesign(
    ConstRef<MatX> centres, const RbfFitOptions& options, material::TrustedStretches trusted)
    : m_options(options)
    , m_trusted(trusted) {
  options.validate();
  trusted.validate("rbf_fit.trusted_stretches");
  if (!options.energy_kernels && trusted.bounded())
    rbf_fit_error(
        "trusted_stretches", "needs energy kernels (stress kernels have no energy to continue)");
  if (centres.rows() < 1 || centres.cols() != 3)
    rbf_fit_error("centres",
        "expected m × 3 with m ≥ 1, got " + to_text(centres.rows()) + " × "
            + to_text(centres.cols()));
  if (!centres.allFinite())
    rbf_fit_error("centres", "contains a non-finite value");
  m_centres = centres;
  if (options.energy_kernels)
    m_energy_kernels = material::EnergyKernelBank(centres, options.epsilon);
  const int m = static_cast<int>(centres.rows());
  m_rest_kernels = VecX::Zero(m);
  // A kernel's stress at rest (equal in every direction for energy kernels, by symmetry).
  if (options.stress_free_rest)
    for (int i = 0; i < m; ++i)
      m_rest_kernels[i] = options.energy_kernels
          ? material::energy_kernel_gradient(
              Vec3::Ones(), centres.row(i).transpose(), options.epsilon)[0]
          : material::rbf_kernel(
              (Vec3::Ones() - centres.row(i).transpose()).squaredNorm(), options.epsilon);
  m_elastic = m;
  if (options.elastic_polynomial) {
    m_elastic += 2;
    if (!options.stress_free_rest)
      m_constant = m_elastic++;
    if (options.quadratic_tail) {
      m_quadratic = m_elastic;
      m_elastic += options.energy_kernels ? 3 : 4;
    }
    if (options.neo_hookean_tail) {
      m_neo_hookean = m_elastic;
      m_elastic += 2;
    }
  }
  m_damping = options.fit_damping
      ? m + (options.damping_polynomial ? 4 : 0) + (options.damping_quadratic_tail ? 3 : 0)
      : 0;
  if (options.smoothness > 0) {
    const auto plain_kernel = [&](int i, int j) {
      return material::rbf_kernel((centres.row(i) - centres.row(j)).squaredNorm(), options.epsilon);
    };
    const auto energy_kernel = [&](int i, int j) {
      return material::energy_kernel(
          centres.row(i).transpose(), centres.row(j).transpose(), options.epsilon);
    };
    m_elastic_seminorm = options.energy_kernels ? unit_trace_seminorm(m, energy_kernel)
                                                : unit_trace_seminorm(m, plain_kernel);
    if (m_damping > 0)
      m_damping_seminorm = unit_trace_seminorm(m, plain_kernel);
  }
  if (m_trusted.smooth()) {
    m_end_stress.setZero(2, m_elastic);
    m_end_stiffness.setZero(2, m_elastic);
    m_end_coupling.setZero(2, m_elastic);
    m_pair_coupling.setZero(3, m_elastic);
    OutputMatrix a(3, m_elastic);
    OutputGradient d(9, m_elastic);
    for (int end = 0; end < 2; ++end)
      if (m_trusted.has_end(end == 0)) {
        formula_matrix(m_trusted.end_point(end == 0), a, d);
        m_end_stress.row(end) = a.row(0);
        m_end_stiffness.row(end) = d.row(0);
        if (m_trusted.continuation == material::Continuation::smooth_expansion)
          m_end_coupling.row(end) = d.row(3); // ∂A(0, ·)/∂σ₁
      }
    if (m_trusted.continuation == material::Continuation::smooth_expansion)
      m_follow = 1;
    for (int e = 0; e < 2 && m_follow == 1; ++e)
      for (int f = e; f < 2; ++f)
        if (m_trusted.has_end(e == 0) && m_trusted.has_end(f == 0)) {
          formula_matrix(m_trusted.pair_point(e == 0, f == 0), a, d);
          m_pair_coupling.row(pair_row(e, f)) = d.row(3);
        }
  }
}

namespace {

/// Columns: the quadratic tail's q of each cubic energy α p₁³, β p₁p₂, γ p₃ (e = σ − 1, p_k the
/// power sums; material::is_energy_quadratic_tail).
const Eigen::Matrix<double, 4, 3>& energy_tail_map() {
  static const Eigen::Matrix<double, 4, 3> map
      = (Eigen::Matrix<double, 4, 3>() << 3, 3, 3, 6, 2, 0, 3, 1, 0, 0, -2, 0).finished();
  return map;
}

} // namespace

void RbfDesign::output_matrix(const Vec3& stretches, Eigen::Ref<OutputMatrix> out) const {
  if (m_trusted.nearest(stretches) != stretches) {
    if (m_trusted.smooth()) {
      formula_columns(m_trusted.formula_stretches(stretches), out);
      thread_local OutputMatrix a, b; // per thread, sized once per design size
      const ClampState c = clamp_state(stretches, a, b);
      clamp_rows(c, a, b, out);
      return;
    }
    // Outside the trusted interval (energy kernels only): the expansion needs ∂A/∂σ. Per
    // thread, sized once per design size: no allocation in the per-element loops.
    thread_local OutputGradient gradient;
    gradient.resize(9, out.cols());
    output_matrix(stretches, out, gradient);
    return;
  }
  formula_columns(stretches, out);
}

RbfDesign::ClampState RbfDesign::clamp_state(
    const Vec3& stretches, OutputMatrix& a, OutputMatrix& b) const {
  ClampState c;
  for (int k = 0; k < 3; ++k) {
    c.stretch[k] = m_trusted.smooth_clamp(stretches[k]);
    c.beyond[k] = stretches[k] > m_trusted.max || stretches[k] < m_trusted.min;
    c.end[k] = end_row(stretches[k]);
    c.distance[k] = stretches[k] - c.stretch[k].value;
    c.offset[k] = c.stretch[k].value - m_trusted.one();
  }
  a.setZero(3, m_elastic);
  b.setZero(3, m_elastic);
  for (int q = 0; q < 3; ++q) {
    for (int i = 0; i < 3; ++i) {
      if (i == q || !c.beyond[i])
        continue;
      b.row(q) += c.distance[i] * m_end_coupling.row(c.end[i]);
      if (c.beyond[q])
        a.row(q) += c.distance[i] * m_pair_coupling.row(pair_row(c.end[q], c.end[i]));
    }
    if (c.beyond[q]) {
      const double from_end = c.stretch[q].value - m_trusted.end_point(c.end[q] == 0)[0];
      a.row(q) += m_end_stress.row(c.end[q])
          + (m_follow * from_end + c.distance[q]) * m_end_stiffness.row(c.end[q])
          + (c.offset.sum() - c.offset[q]) * m_end_coupling.row(c.end[q]);
      b.row(q) += m_follow * c.distance[q] * m_end_stiffness.row(c.end[q]);
    }
  }
  return c;
}

void RbfDesign::clamp_rows(const ClampState& c, const OutputMatrix& a, const OutputMatrix& b,
    Eigen::Ref<OutputMatrix> out) const {
  // Row q: φ'_q (A_q(φ) + b_q) + (1 − φ'_q) a_q (material::smoothly_clamped_correction).
  for (int q = 0; q < 3; ++q)
    out.row(q) = c.stretch[q].slope * (out.row(q) + b.row(q)) + (1 - c.stretch[q].slope) * a.row(q);
}

void RbfDesign::clamp_gradient(const ClampState& c, const OutputMatrix& a, const OutputMatrix& b,
    Eigen::Ref<const OutputMatrix> out, Eigen::Ref<OutputGradient> gradient) const {
  // Row 3r + q is ∂A(q, ·)/∂σ_r: φ'_q φ'_r ∂A(q, ·)/∂φ_r, plus, for r = q,
  // φ''_q (A_q(φ) − a_q + b_q) + (1 − φ'_q)(1 − φ'_q + 2 f φ'_q) K_q, and for r ≠ q
  // (1 − φ'_q) L_q φ'_r + φ'_q (1 − φ'_r) L_r + (1 − φ'_q)(1 − φ'_r) M_qr.
  for (int q = 0; q < 3; ++q)
    for (int r = 0; r < 3; ++r)
      gradient.row(3 * r + q) *= c.stretch[q].slope * c.stretch[r].slope;
  for (int q = 0; q < 3; ++q) {
    const double sq = c.stretch[q].slope;
    if (c.beyond[q])
      gradient.row(3 * q + q) += c.stretch[q].curvature * (out.row(q) - a.row(q) + b.row(q))
          + (1 - sq) * (1 - sq + 2 * m_follow * sq) * m_end_stiffness.row(c.end[q]);
    for (int r = 0; r < 3; ++r) {
      if (r == q)
        continue;
      const double sr = c.stretch[r].slope;
      if (c.beyond[q])
        gradient.row(3 * r + q) += (1 - sq) * sr * m_end_coupling.row(c.end[q]);
      if (c.beyond[r])
        gradient.row(3 * r + q) += sq * (1 - sr) * m_end_coupling.row(c.end[r]);
      if (c.beyond[q] && c.beyond[r])
        gradient.row(3 * r + q)
            += (1 - sq) * (1 - sr) * m_pair_coupling.row(pair_row(c.end[q], c.end[r]));
    }
  }
}

void RbfDesign::formula_columns(const Vec3& stretches, Eigen::Ref<OutputMatrix> out) const {
  if (m_options.energy_kernels) {
    const Eigen::Index m = m_centres.rows();
    m_energy_kernels.evaluate(stretches, out.leftCols(m));
    out.leftCols(m).rowwise() -= m_rest_kernels.transpose();
  }
  view_columns(stretches, out);
}

void RbfDesign::view_columns(const Vec3& stretches, Eigen::Ref<OutputMatrix> out) const {
  const Eigen::Index m = m_centres.rows();
  const double eps = m_options.epsilon;
  for (int k = 0; k < 3; ++k) {
    const Vec3 y = material::stretch_view(stretches, k);
    if (!m_options.energy_kernels)
      for (Eigen::Index i = 0; i < m; ++i)
        out(k, i) = material::rbf_kernel((y - m_centres.row(i).transpose()).squaredNorm(), eps)
            - m_rest_kernels[i];
    if (m_options.elastic_polynomial) {
      out(k, m) = y[0] - 1;
      out(k, m + 1) = y[1] + y[2] - 2;
      if (m_constant >= 0)
        out(k, m_constant) = 1;
      if (m_quadratic >= 0) {
        const Eigen::RowVector4d t = material::quadratic_tail_basis(y).transpose();
        if (m_options.energy_kernels)
          out.block<1, 3>(k, m_quadratic) = t * energy_tail_map();
        else
          out.block<1, 4>(k, m_quadratic) = t;
      }
      if (m_neo_hookean >= 0)
        out.block<1, 2>(k, m_neo_hookean) = material::neo_hookean_tail_basis(y).transpose();
    }
  }
}

void RbfDesign::output_matrix(const Vec3& stretches, Eigen::Ref<OutputMatrix> out,
    Eigen::Ref<OutputGradient> gradient) const {
  const Vec3 c = m_trusted.nearest(stretches);
  if (c != stretches && m_trusted.smooth()) {
    formula_matrix(m_trusted.formula_stretches(stretches), out, gradient);
    thread_local OutputMatrix a, b; // per thread, sized once per design size
    const ClampState state = clamp_state(stretches, a, b);
    clamp_gradient(state, a, b, out, gradient);
    clamp_rows(state, a, b, out);
    return;
  }
  formula_matrix(c, out, gradient);
  if (c == stretches)
    return;
  const Vec3 d = stretches - c;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k)
      out.row(k) += d[j] * gradient.row(3 * j + k);
}

void RbfDesign::formula_matrix(const Vec3& stretches, Eigen::Ref<OutputMatrix> out,
    Eigen::Ref<OutputGradient> gradient) const {
  view_columns(stretches, out);
  gradient.setZero();
  const Eigen::Index m = m_centres.rows();
  for (int k = 0; k < 3; ++k) {
    const auto idx = material::stretch_view_indices(stretches, k);
    const Vec3 y(stretches[idx[0]], stretches[idx[1]], stretches[idx[2]]);
    // ∂/∂σ_idx[c] of the view's entry c; collect into row 3 idx[c] + k.
    const auto add = [&](Eigen::Index column, const Vec3& d_y) {
      for (int c = 0; c < 3; ++c)
        gradient(3 * idx[c] + k, column) += d_y[c];
    };
    if (!m_options.energy_kernels)
      for (Eigen::Index i = 0; i < m; ++i) {
        const Vec3 d = y - m_centres.row(i).transpose();
        const double phi = out(k, i) + m_rest_kernels[i];
        if (phi > 0)
          add(i, d / phi);
      }
    if (m_options.elastic_polynomial) {
      add(m, Vec3(1, 0, 0));
      add(m + 1, Vec3(0, 1, 1));
      if (m_quadratic >= 0) {
        const double e = y[0] - 1, s = y[1] + y[2] - 2;
        const Eigen::Matrix<double, 3, 4> d_t = (Eigen::Matrix<double, 3, 4>() << 2 * e, s, 0, 0, 0,
            e, 2 * s, y[2] - 1, 0, e, 2 * s, y[1] - 1)
                                                    .finished(); // column j: ∂t_j/∂y
        if (m_options.energy_kernels)
          for (int c = 0; c < 3; ++c)
            add(m_quadratic + c, d_t * energy_tail_map().col(c));
        else
          for (int c = 0; c < 4; ++c)
            add(m_quadratic + c, d_t.col(c));
      }
      if (m_neo_hookean >= 0) {
        Eigen::Matrix<double, 2, 3> d_g;
        material::neo_hookean_tail_basis(y, &d_g);
        add(m_neo_hookean, d_g.row(0).transpose());
        add(m_neo_hookean + 1, d_g.row(1).transpose());
      }
    }
  }
  // Column i of `gradient`: ∂N_k/∂σ_j of kernel i alone (row 3j + k).
  if (m_options.energy_kernels) {
    m_energy_kernels.evaluate(stretches, out.leftCols(m), gradient.leftCols(m));
    out.leftCols(m).rowwise() -= m_rest_kernels.transpose();
  }
}

void RbfDesign::damping_row(const Vec3& stretches, Eigen::Ref<Eigen::RowVectorXd> out) const {
  if (m_damping == 0)
    return;
  const Eigen::Index m = m_centres.rows();
  Vec3 s = m_trusted.formula_stretches(stretches);
  std::sort(s.data(), s.data() + 3, std::greater<>());
  for (Eigen::Index i = 0; i < m; ++i)
    out[i]
        = material::rbf_kernel((s - m_centres.row(i).transpose()).squaredNorm(), m_options.epsilon);
  if (m_options.damping_polynomial) {
    out.segment<3>(m) = (s - Vec3::Ones()).transpose();
    out[m + 3] = 1;
    if (m_options.damping_quadratic_tail)
      out.segment<3>(m + 4) = (s - Vec3::Ones()).cwiseAbs2().transpose();
  }
}

material::RbfCorrection RbfDesign::correction(ConstRef<VecX> x) const {
  ELASTOLEARN_CHECK(x.size() == num_unknowns(), "RbfDesign::correction: wrong unknown count");
  const Eigen::Index m = m_centres.rows();
  material::RbfCorrection::Parameters p;
  p.centres = m_centres;
  p.epsilon = m_options.epsilon;
  p.energy_kernels = m_options.energy_kernels;
  p.trusted = m_trusted;
  p.weights = x.head(m);
  p.constant = -p.weights.dot(m_rest_kernels); // N(1) = 0 under stress_free_rest
  if (m_options.elastic_polynomial) {
    p.own_slope = x[m];
    p.other_slope = x[m + 1];
    if (m_constant >= 0)
      p.constant = x[m_constant];
    if (m_quadratic >= 0)
      p.quadratic = m_options.energy_kernels
          ? Eigen::Vector4d(energy_tail_map() * x.segment<3>(m_quadratic))
          : Eigen::Vector4d(x.segment<4>(m_quadratic));
    if (m_neo_hookean >= 0)
      p.neo_hookean = x.segment<2>(m_neo_hookean);
  }
  if (m_damping > 0) {
    const auto v = x.segment(m_elastic, m_damping);
    p.damping_weights = v.head(m);
    if (m_options.damping_polynomial) {
      p.damping_slopes = v.segment<3>(m);
      p.damping_constant = v[m + 3];
      if (m_options.damping_quadratic_tail)
        p.damping_quadratic = v.segment<3>(m + 4);
    }
    p.damping_floor = m_options.damping_floor;
  }
  if (m_options.mass_damping)
    p.mass_damping = x[mass_damping_unknown()];
  return material::RbfCorrection(std::move(p));
}

VecX RbfDesign::unknowns(const material::RbfCorrection& c) const {
  const auto& p = c.parameters();
  const Eigen::Index m = m_centres.rows();
  if (p.centres.rows() != m || p.centres != m_centres || p.epsilon != m_options.epsilon
      || p.energy_kernels != m_options.energy_kernels || p.trusted.min != m_trusted.min
      || p.trusted.max != m_trusted.max)
    rbf_fit_error("correction",
        "its centres, kernel smoothing, kernel kind or trusted stretches differ from the design's");
  const bool has_tail = p.own_slope != 0 || p.other_slope != 0 || !p.quadratic.isZero();
  const bool has_damping_tail
      = !p.damping_slopes.isZero(0) || p.damping_constant != 0 || !p.damping_quadratic.isZero(0);
  const bool has_damping = p.damping_weights.size() > 0 || has_damping_tail;
  if ((has_tail && !m_options.elastic_polynomial) || (!p.quadratic.isZero() && m_quadratic < 0)
      || (!p.neo_hookean.isZero() && m_neo_hookean < 0) || (has_damping && m_damping == 0)
      || (p.mass_damping != 0 && !m_options.mass_damping))
    rbf_fit_error("correction", "it has a term the design does not fit");
  VecX x = VecX::Zero(num_unknowns());
  x.head(m) = p.weights;
  if (m_options.elastic_polynomial) {
    x[m] = p.own_slope;
    x[m + 1] = p.other_slope;
    if (m_constant >= 0)
      x[m_constant] = p.constant;
    if (m_quadratic >= 0 && m_options.energy_kernels) {
      // Invert energy_tail_map on its range (q₁ = 2 q₂, which the correction guarantees).
      const Eigen::Vector4d& q = p.quadratic;
      const double beta = -0.5 * q[3], alpha = (q[2] - beta) / 3;
      x.segment<3>(m_quadratic) = Vec3(alpha, beta, (q[0] - 3 * alpha - 3 * beta) / 3);
    } else if (m_quadratic >= 0) {
      x.segment<4>(m_quadratic) = p.quadratic;
    }
    if (m_neo_hookean >= 0)
      x.segment<2>(m_neo_hookean) = p.neo_hookean;
  }
  const double prestress = p.constant + p.weights.dot(m_rest_kernels);
  if (m_constant < 0
      && std::abs(prestress)
          > 1e-9 * (std::abs(p.constant) + p.weights.cwiseAbs().dot(m_rest_kernels.cwiseAbs()) + 1))
    rbf_fit_error(
        "correction", "it is not stress-free at rest (N(1) = " + to_text(prestress) + " Pa)");
  if (m_damping > 0) {
    if (p.damping_weights.size() == m)
      x.segment(m_elastic, m) = p.damping_weights;
    if (m_options.damping_polynomial) {
      x.segment<3>(m_elastic + m) = p.damping_slopes;
      x[m_elastic + m + 3] = p.damping_constant;
      if (m_options.damping_quadratic_tail)
        x.segment<3>(m_elastic + m + 4) = p.damping_quadratic;
      else if (!p.damping_quadratic.isZero(0))
        rbf_fit_error("correction", "it has a quadratic damping tail the design does not fit");
    } else if (has_damping_tail)
      rbf_fit_error("correction", "it has a damping tail the design does not fit");
  }
  if (m_options.mass_damping)
    x[mass_damping_unknown()] = p.mass_damping;
  return x;
}

MatX stretch_views(ConstRef<MatX> stretches) {
  ELASTOLEARN_CHECK(stretches.cols() == 3, "stretch_views: N × 3 expected");
  MatX out(3 * stretches.rows(), 3);
  for (Eigen::Index j = 0; j < stretches.rows(); ++j)
    for (int k = 0; k < 3; ++k)
      out.row(3 * j + k) = material::stretch_view(stretches.row(j).transpose(), k).transpose();
  return out;
}

VecX RbfDesign::regularization_weights() const {
  VecX w(num_unknowns());
  w.head(m_elastic).setConstant(m_options.regularization);
  w.segment(m_elastic, m_damping).setConstant(m_options.damping_regularization);
  if (m_options.mass_damping)
    w[mass_damping_unknown()] = m_options.damping_regularization;
  return w;
}

MatX RbfDesign::smoothness_penalty(ConstRef<MatX> normal) const {
  const Eigen::Index u = normal.rows();
  ELASTOLEARN_CHECK(normal.cols() == u && (u == m_elastic || u == num_unknowns()),
      "smoothness_penalty: the normal matrix must cover the elastic or all unknowns");
  MatX penalty = MatX::Zero(u, u);
  if (m_options.smoothness == 0)
    return penalty;
  const int m = num_centres();
  penalty.topLeftCorner(m, m)
      = m_options.smoothness * normal.topLeftCorner(m, m).trace() * m_elastic_seminorm;
  if (u > m_elastic && m_damping > 0)
    penalty.block(m_elastic, m_elastic, m, m) = m_options.smoothness
        * normal.block(m_elastic, m_elastic, m, m).trace() * m_damping_seminorm;
  return penalty;
}

RegularisedNormalEquations::RegularisedNormalEquations(
    MatX normal, ConstRef<VecX> regularization, long samples)
    : m_scale(normal.diagonal().cwiseSqrt()) {
  const Eigen::Index u = normal.rows();
  // Jacobi scaling, then Tikhonov on the scaled unknowns (λ dimensionless).
  for (Eigen::Index i = 0; i < u; ++i)
    if (!(m_scale[i] > 0))
      m_scale[i] = 1; // an unused unknown (e.g. no stretch rate): only λ constrains it
  normal = m_scale.cwiseInverse().asDiagonal() * normal * m_scale.cwiseInverse().asDiagonal();
  normal.diagonal() += regularization;
  m_llt.compute(normal);
  if (m_llt.info() != Eigen::Success)
    rbf_fit_error("regularization",
        "the normal equations are singular (" + to_text(samples) + " samples, " + to_text(u)
            + " unknowns); increase the regularisation or give more varied samples");
}

MatX RegularisedNormalEquations::solve(ConstRef<MatX> rhs) const {
  const MatX scaled = rhs.array().colwise() / m_scale.array();
  MatX x = m_llt.solve(scaled).array().colwise() / m_scale.array();
  if (!x.allFinite())
    rbf_fit_error(
        "regularization", "the fit produced non-finite weights; increase the regularisation");
  return x;
}

VecX solve_regularised_normal_equations(
    MatX normal, ConstRef<VecX> rhs, ConstRef<VecX> regularization, long samples) {
  return RegularisedNormalEquations(std::move(normal), regularization, samples).solve(rhs);
}

RbfFitResult fit_rbf_correction(const RbfDesign& design, const StressSamples& samples) {
  const Eigen::Index n = samples.stretches.rows();
  if (n == 0)
    rbf_fit_error("samples", "no samples to fit");
  if (samples.stretch_rates.rows() != n || samples.targets.rows() != n)
    rbf_fit_error("samples",
        to_text(n) + " stretch samples but " + to_text(samples.stretch_rates.rows())
            + " stretch rates and " + to_text(samples.targets.rows()) + " targets");
  if (!samples.stretches.allFinite() || !samples.stretch_rates.allFinite()
      || !samples.targets.allFinite())
    rbf_fit_error("samples", "contain a non-finite value");
  const int u = design.elastic_unknowns();
  MatX normal = MatX::Zero(u, u);
  VecX rhs = VecX::Zero(u);
  MatX stacked(3 * k_chunk, u);
  VecX targets(3 * k_chunk);
  RbfDesign::OutputMatrix a(3, u);
  for (Eigen::Index start = 0; start < n; start += k_chunk) {
    const Eigen::Index c = std::min(k_chunk, n - start);
    for (Eigen::Index j = 0; j < c; ++j) {
      design.output_matrix(samples.stretches.row(start + j).transpose(), a);
      stacked.middleRows(3 * j, 3) = a;
      targets.segment<3>(3 * j) = samples.targets.row(start + j).transpose();
    }
    const auto rows = stacked.topRows(3 * c);
    normal.selfadjointView<Eigen::Lower>().rankUpdate(rows.transpose());
    rhs.noalias() += rows.transpose() * targets.head(3 * c);
  }
  normal.triangularView<Eigen::StrictlyUpper>() = normal.transpose();
  normal += design.smoothness_penalty(normal);
  VecX x = VecX::Zero(design.num_unknowns());
  x.head(u)
      = solve_regularised_normal_equations(normal, rhs, design.regularization_weights().head(u), n);
  RbfFitResult result { design.correction(x), x, 0, 0, static_cast<int>(n) };
  double residual = 0, target = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const Vec3 y_j = samples.targets.row(j).transpose();
    const Vec3 n_j = result.correction.correction(
        samples.stretches.row(j).transpose(), samples.stretch_rates.row(j).transpose());
    residual += (n_j - y_j).squaredNorm();
    target += y_j.squaredNorm();
  }
  result.rms_residual = std::sqrt(residual / double(n));
  result.rms_target = std::sqrt(target / double(n));
  return result;
}

} // namespace elastolearn::learn
