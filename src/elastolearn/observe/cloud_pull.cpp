#include <elastolearn/observe/cloud_pull.hpp>

#include <elastolearn/core/error.hpp>

#include <algorithm>

namespace elastolearn::observe {

CloudPull::CloudPull(const capture::SurfaceSamples& samples, const fem::DofMap& dofs,
    const fem::SystemMatrix& pattern)
    : m_samples(samples)
    , m_num_vertices(dofs.num_dofs() / 3)
    , m_weight(VecX::Zero(samples.num_samples()))
    , m_target(Positions::Zero(samples.num_samples(), 3))
    , m_metric(static_cast<std::size_t>(samples.num_samples()), Mat3::Identity())
    , m_slots(static_cast<std::size_t>(81) * static_cast<std::size_t>(samples.num_samples()), -1)
    , m_values(VecX::Zero(pattern.nonzeros())) {
  const fem::SparseMatrix& A = pattern.matrix();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const auto slot = [&](int row, int col) {
    const int* begin = inner + outer[col];
    const int* end = inner + outer[col + 1];
    const int* found = std::lower_bound(begin, end, row);
    ELASTOLEARN_CHECK(found != end && *found == row,
        "cloud pull: a surface triangle's vertex pair is missing from the system pattern");
    return static_cast<int>(found - inner);
  };
  for (int k = 0; k < samples.num_samples(); ++k)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int vi = samples.vertices(k, i), vj = samples.vertices(k, j);
        ELASTOLEARN_CHECK(vi >= 0 && vi < m_num_vertices && vj >= 0 && vj < m_num_vertices,
            "cloud pull: sample vertex out of range");
        if (samples.weights(k, i) == 0 || samples.weights(k, j) == 0)
          continue;
        const int ri = dofs.free_index(3 * vi), cj = dofs.free_index(3 * vj);
        if (ri < 0 || cj < 0)
          continue;
        for (int d = 0; d < 3; ++d)
          for (int e = 0; e < 3; ++e)
            m_slots[static_cast<std::size_t>(81 * k + 27 * i + 9 * j + 3 * d + e)]
                = slot(ri + d, cj + e);
      }
}

void CloudPull::clear() {
  for (int k : m_active) {
    m_weight[k] = 0;
    m_target.row(k).setZero();
  }
  m_active.clear();
  m_constant = 0;
}

void CloudPull::set_pairs(ConstRef<Positions> cloud,
    const std::vector<capture::Correspondence>& pairs, double stiffness,
    ConstRef<Positions> normals, double tangential_weight) {
  ELASTOLEARN_CHECK(stiffness > 0, "cloud pull: the stiffness must be positive");
  ELASTOLEARN_CHECK(tangential_weight >= 0 && tangential_weight <= 1,
      "cloud pull: the tangential weight must be in [0, 1]");
  const bool point_to_point = tangential_weight == 1;
  ELASTOLEARN_CHECK(
      point_to_point || (normals.rows() == m_samples.num_samples() && normals.cols() == 3),
      "cloud pull: one normal per sample");
  clear();
  for (const capture::Correspondence& c : pairs) {
    const double w = stiffness * c.weight;
    if (m_weight[c.sample] == 0 && w != 0) {
      m_active.push_back(c.sample);
      Mat3& metric = m_metric[static_cast<std::size_t>(c.sample)];
      metric = Mat3::Identity();
      if (!point_to_point) {
        const Vec3 n = normals.row(c.sample).transpose();
        metric = tangential_weight * metric + (1 - tangential_weight) * n * n.transpose();
      }
    }
    m_weight[c.sample] += w;
    m_target.row(c.sample) += w * cloud.row(c.point);
    const Vec3 p = cloud.row(c.point).transpose();
    m_constant += 0.5 * w * p.dot(m_metric[static_cast<std::size_t>(c.sample)] * p);
  }
  std::sort(m_active.begin(), m_active.end());
  m_active.erase(std::unique(m_active.begin(), m_active.end()), m_active.end());
}

double CloudPull::energy(const VecX& x) const {
  // (κ/2) Σ w (c − s)ᵀA(c − s) = Σ_k (½ W_k s_kᵀA_k s_k − T_kᵀA_k s_k) + ½ κ Σ w cᵀA c.
  const Eigen::Map<const Positions> X(x.data(), m_num_vertices, 3);
  double e = m_constant;
  for (int k : m_active) {
    Vec3 s = Vec3::Zero();
    for (int j = 0; j < 3; ++j)
      s += m_samples.weights(k, j) * X.row(m_samples.vertices(k, j)).transpose();
    const Vec3 as = m_metric[static_cast<std::size_t>(k)] * s;
    e += 0.5 * m_weight[k] * s.dot(as) - m_target.row(k).dot(as);
  }
  return e;
}

void CloudPull::add_force(const fem::ForceState& state, VecX& f) {
  const Eigen::Map<const Positions> X(state.x.data(), m_num_vertices, 3);
  Eigen::Map<Positions> F(f.data(), m_num_vertices, 3);
  for (int k : m_active) {
    Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
    for (int j = 0; j < 3; ++j)
      s += m_samples.weights(k, j) * X.row(m_samples.vertices(k, j));
    const Eigen::RowVector3d pull
        = (m_target.row(k) - m_weight[k] * s) * m_metric[static_cast<std::size_t>(k)];
    for (int j = 0; j < 3; ++j)
      F.row(m_samples.vertices(k, j)) += m_samples.weights(k, j) * pull;
  }
}

void CloudPull::add_jacobian(const fem::ForceState&, double c_x, double, fem::SystemMatrix& A) {
  if (m_active.empty() || c_x == 0)
    return;
  m_values.setZero();
  for (int k : m_active) {
    const Mat3& a = m_metric[static_cast<std::size_t>(k)];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double h = m_weight[k] * m_samples.weights(k, i) * m_samples.weights(k, j);
        const int* slots = &m_slots[static_cast<std::size_t>(81 * k + 27 * i + 9 * j)];
        for (int d = 0; d < 3; ++d)
          for (int e = 0; e < 3; ++e)
            if (slots[3 * d + e] >= 0)
              m_values[slots[3 * d + e]] += h * a(d, e);
      }
  }
  A.add_values(m_values, c_x);
}

} // namespace elastolearn::observe
