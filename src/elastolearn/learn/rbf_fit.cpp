#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/rbf_fit.hpp>

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace elastolearn::learn {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw InputError("rbf_fit." + field, what);
}

template <typename T> std::string str(T v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Sample j in descending stretch order (stable), its rates and target permuted alike.
void sorted_sample(const StressSamples& samples, Eigen::Index j, Vec3& s, Vec3& f, Vec3& y) {
  const Vec3 s0 = samples.stretches.row(j).transpose();
  std::array<int, 3> p { 0, 1, 2 };
  std::stable_sort(p.begin(), p.end(), [&](int a, int b) { return s0[a] > s0[b]; });
  for (int i = 0; i < 3; ++i) {
    s[i] = s0[p[i]];
    f[i] = samples.stretch_rates(j, p[i]);
    y[i] = samples.targets(j, p[i]);
  }
}

constexpr Eigen::Index k_chunk = 2048;

} // namespace

void RbfFitOptions::validate() const {
  if (!std::isfinite(epsilon) || epsilon < 0)
    fail("epsilon", "must be finite and ≥ 0, got " + str(epsilon));
  if (!std::isfinite(regularization) || regularization < 0)
    fail("regularization", "must be finite and ≥ 0, got " + str(regularization));
  if (!damping_tangent.allFinite())
    fail("damping_tangent", "contains a non-finite value");
}

RbfDesign::RbfDesign(ConstRef<MatX> centres, const RbfFitOptions& options)
    : m_options(options) {
  options.validate();
  if (centres.rows() < 1 || centres.cols() != 3) {
    fail("centres",
        "expected m × 3 with m ≥ 1, got " + str(centres.rows()) + " × " + str(centres.cols()));
  }
  if (!centres.allFinite())
    fail("centres", "contains a non-finite value");
  m_centres = centres;
  const int m = static_cast<int>(centres.rows());
  m_elastic = m + (options.elastic_polynomial ? 4 : 0);
  m_damping = options.fit_damping ? m + (options.damping_polynomial ? 4 : 0) : 0;
}

void RbfDesign::features(const Vec3& s, Eigen::Ref<VecX> out) const {
  const Eigen::Index m = m_centres.rows();
  const double eps = m_options.epsilon;
  for (Eigen::Index i = 0; i < m; ++i)
    out[i] = material::rbf_kernel((s - m_centres.row(i).transpose()).squaredNorm(), eps);
  out.segment<3>(m) = s.array() - 1.0;
  out[m + 3] = 1.0;
}

material::RbfCorrection RbfDesign::correction(ConstRef<VecX> x) const {
  ELASTOLEARN_CHECK(x.size() == num_unknowns(), "RbfDesign::correction: wrong unknown count");
  const Eigen::Index m = m_centres.rows();
  material::RbfCorrection::Parameters p;
  p.centres = m_centres;
  p.epsilon = m_options.epsilon;
  p.weights.resize(m, 3);
  for (int k = 0; k < 3; ++k) {
    const auto w = x.segment(Eigen::Index(k) * m_elastic, m_elastic);
    p.weights.col(k) = w.head(m);
    if (m_options.elastic_polynomial) {
      p.linear.row(k) = w.segment<3>(m).transpose();
      p.constant[k] = w[m + 3];
    }
  }
  if (m_damping > 0) {
    const auto v = x.tail(m_damping);
    p.damping_weights = v.head(m);
    if (m_options.damping_polynomial) {
      p.damping_linear = v.segment<3>(m);
      p.damping_constant = v[m + 3];
    }
    p.damping_tangent = m_options.damping_tangent;
  }
  return material::RbfCorrection(std::move(p));
}

RbfFitResult fit_rbf_correction(const RbfDesign& design, const StressSamples& samples) {
  const Eigen::Index n = samples.stretches.rows();
  if (n == 0)
    fail("samples", "no samples to fit");
  if (samples.stretch_rates.rows() != n || samples.targets.rows() != n) {
    fail("samples",
        str(n) + " stretch samples but " + str(samples.stretch_rates.rows()) + " stretch rates and "
            + str(samples.targets.rows()) + " targets");
  }
  if (!samples.stretches.allFinite() || !samples.stretch_rates.allFinite()
      || !samples.targets.allFinite()) {
    fail("samples", "contain a non-finite value");
  }
  const int q = design.num_features();
  const int qe = design.elastic_features();
  const int qd = design.damping_features();
  const bool damping = qd > 0;
  const Mat3& D = design.options().damping_tangent;

  // Normal equations from the feature matrix B (rows b(σ_j)ᵀ) and g_j = D ḟ_j:
  //   W_k–W_k: Σ b bᵀ,  W_k–V: Σ g_k b bᵀ,  V–V: Σ ‖g‖² b bᵀ;  rhs W_k: Σ y_k b,  V: Σ (g·y) b.
  MatX gram = MatX::Zero(q, q), gram_d = MatX::Zero(q, q);
  std::array<MatX, 3> gram_k { MatX::Zero(q, q), MatX::Zero(q, q), MatX::Zero(q, q) };
  MatX rhs_w = MatX::Zero(q, 3);
  VecX rhs_v = VecX::Zero(q);
  MatX b(k_chunk, q), weighted(k_chunk, q);
  MatX g(k_chunk, 3), y(k_chunk, 3);
  VecX row(q);
  for (Eigen::Index start = 0; start < n; start += k_chunk) {
    const Eigen::Index c = std::min(k_chunk, n - start);
    for (Eigen::Index j = 0; j < c; ++j) {
      Vec3 s, f, target;
      sorted_sample(samples, start + j, s, f, target);
      design.features(s, row);
      b.row(j) = row.transpose();
      g.row(j) = (D * f).transpose();
      y.row(j) = target.transpose();
    }
    const auto bc = b.topRows(c);
    gram.selfadjointView<Eigen::Lower>().rankUpdate(bc.transpose());
    rhs_w.noalias() += bc.transpose() * y.topRows(c);
    if (!damping)
      continue;
    for (int k = 0; k < 3; ++k) {
      weighted.topRows(c) = bc.array().colwise() * g.col(k).head(c).array();
      gram_k[k].noalias() += bc.transpose() * weighted.topRows(c);
    }
    const VecX g2 = g.topRows(c).rowwise().squaredNorm();
    weighted.topRows(c) = bc.array().colwise() * g2.array();
    gram_d.noalias() += bc.transpose() * weighted.topRows(c);
    rhs_v.noalias() += bc.transpose() * (g.topRows(c).cwiseProduct(y.topRows(c))).rowwise().sum();
  }
  gram.triangularView<Eigen::StrictlyUpper>() = gram.transpose();

  const int u = design.num_unknowns();
  MatX normal = MatX::Zero(u, u);
  VecX rhs(u);
  for (int k = 0; k < 3; ++k) {
    normal.block(k * qe, k * qe, qe, qe) = gram.topLeftCorner(qe, qe);
    rhs.segment(k * qe, qe) = rhs_w.col(k).head(qe);
    if (damping) {
      normal.block(k * qe, 3 * qe, qe, qd) = gram_k[k].topLeftCorner(qe, qd);
      normal.block(3 * qe, k * qe, qd, qe) = gram_k[k].topLeftCorner(qe, qd).transpose();
    }
  }
  if (damping) {
    normal.bottomRightCorner(qd, qd) = gram_d.topLeftCorner(qd, qd);
    rhs.tail(qd) = rhs_v.head(qd);
  }

  // Jacobi scaling, then Tikhonov on the scaled unknowns.
  VecX scale = normal.diagonal().cwiseSqrt();
  for (Eigen::Index i = 0; i < u; ++i) {
    if (!(scale[i] > 0))
      scale[i] = 1; // an unused unknown (e.g. no stretch rate): only λ constrains it
  }
  MatX scaled = scale.cwiseInverse().asDiagonal() * normal * scale.cwiseInverse().asDiagonal();
  scaled.diagonal().array() += design.options().regularization;
  const Eigen::LLT<MatX> llt(scaled);
  if (llt.info() != Eigen::Success) {
    fail("regularization",
        "the normal equations are singular (" + str(n) + " samples, " + str(u)
            + " unknowns); increase the regularisation or give more varied samples");
  }
  const VecX x = (llt.solve(rhs.cwiseQuotient(scale))).cwiseQuotient(scale);
  if (!x.allFinite())
    fail("regularization", "the fit produced non-finite weights; increase the regularisation");

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
