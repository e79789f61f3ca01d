#include <elastolearn/fem/dof_map.hpp>

namespace elastolearn::fem {

DofMap::DofMap(int num_vertices, const std::vector<int>& prescribed_vertices)
    : m_free_index(3 * num_vertices, 0) {
  for (int v : prescribed_vertices)
    for (int k = 0; k < 3; ++k)
      m_free_index[3 * v + k] = -1;
  int next = 0;
  for (int d = 0; d < 3 * num_vertices; ++d) {
    if (m_free_index[d] < 0)
      continue;
    m_free_index[d] = next++;
    m_free_dofs.push_back(d);
  }
}

VecX DofMap::restrict(const VecX& full) const {
  VecX out;
  restrict_into(full, out);
  return out;
}

void DofMap::restrict_into(const VecX& full, VecX& reduced) const {
  reduced.resize(num_free());
  for (int i = 0; i < num_free(); ++i)
    reduced[i] = full[m_free_dofs[i]];
}

} // namespace elastolearn::fem
