#include <elastolearn/fem/dof_map.hpp>

namespace elastolearn::fem {

DofMap::DofMap(int num_vertices, const std::vector<int>& prescribed_vertices)
    : m_free_index(3 * num_vertices, 0) {
  for (int v : prescribed_vertices)
    for (int k = 0; k < 3; ++k) m_free_index[3 * v + k] = -1;
  int next = 0;
  for (int d = 0; d < 3 * num_vertices; ++d) {
    if (m_free_index[d] < 0) continue;
    m_free_index[d] = next++;
    m_free_dofs.push_back(d);
  }
}

VecX DofMap::restrict(const VecX& full) const {
  VecX out(num_free());
  for (int i = 0; i < num_free(); ++i) out[i] = full[m_free_dofs[i]];
  return out;
}

void DofMap::add_expanded(const VecX& reduced, double scale, VecX& full) const {
  for (int i = 0; i < num_free(); ++i) full[m_free_dofs[i]] += scale * reduced[i];
}

} // namespace elastolearn::fem
