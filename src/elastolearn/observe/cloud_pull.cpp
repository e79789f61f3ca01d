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
    , m_slots(static_cast<std::size_t>(27) * static_cast<std::size_t>(samples.num_samples()), -1)
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
          m_slots[static_cast<std::size_t>(27 * k + 9 * i + 3 * j + d)] = slot(ri + d, cj + d);
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
    const std::vector<capture::Correspondence>& pairs, double stiffness) {
  ELASTOLEARN_CHECK(stiffness > 0, "cloud pull: the stiffness must be positive");
  clear();
  for (const capture::Correspondence& c : pairs) {
    const double w = stiffness * c.weight;
    if (m_weight[c.sample] == 0 && w != 0)
      m_active.push_back(c.sample);
    m_weight[c.sample] += w;
    m_target.row(c.sample) += w * cloud.row(c.point);
    m_constant += 0.5 * w * cloud.row(c.point).squaredNorm();
  }
  std::sort(m_active.begin(), m_active.end());
  m_active.erase(std::unique(m_active.begin(), m_active.end()), m_active.end());
}

double CloudPull::energy(const VecX& x) const {
  // (κ/2) Σ w ‖c − s‖² = Σ_k (½ W_k ‖s_k‖² − T_k · s_k) + ½ κ Σ w ‖c‖².
  const Eigen::Map<const Positions> X(x.data(), m_num_vertices, 3);
  double e = m_constant;
  for (int k : m_active) {
    Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
    for (int j = 0; j < 3; ++j)
      s += m_samples.weights(k, j) * X.row(m_samples.vertices(k, j));
    e += 0.5 * m_weight[k] * s.squaredNorm() - m_target.row(k).dot(s);
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
    const Eigen::RowVector3d pull = m_target.row(k) - m_weight[k] * s;
    for (int j = 0; j < 3; ++j)
      F.row(m_samples.vertices(k, j)) += m_samples.weights(k, j) * pull;
  }
}

void CloudPull::add_jacobian(const fem::ForceState&, double c_x, double, fem::SystemMatrix& A) {
  if (m_active.empty() || c_x == 0)
    return;
  m_values.setZero();
  for (int k : m_active)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double h = m_weight[k] * m_samples.weights(k, i) * m_samples.weights(k, j);
        const int* slots = &m_slots[static_cast<std::size_t>(27 * k + 9 * i + 3 * j)];
        for (int d = 0; d < 3; ++d)
          if (slots[d] >= 0)
            m_values[slots[d]] += h;
      }
  A.add_values(m_values, c_x);
}

} // namespace elastolearn::observe
