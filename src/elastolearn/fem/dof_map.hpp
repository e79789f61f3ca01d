#pragma once
/// \file Which degrees of freedom are unknowns. Fixed and keyframed (prescribed) vertices are
/// removed from the linear system; the rest are numbered consecutively in vertex order.
#include <elastolearn/core/types.hpp>

#include <vector>

namespace elastolearn::fem {

class DofMap {
  public:
  DofMap() = default;
  /// \param num_vertices  n
  /// \param prescribed_vertices  vertices whose positions are given (fixed or keyframed)
  DofMap(int num_vertices, const std::vector<int>& prescribed_vertices);

  int num_dofs() const { return static_cast<int>(m_free_index.size()); } ///< 3n
  int num_free() const { return static_cast<int>(m_free_dofs.size()); } ///< unknowns
  /// Index of dof d among the unknowns, or −1 if prescribed.
  int free_index(int dof) const { return m_free_index[dof]; }
  bool is_prescribed_vertex(int v) const { return m_free_index[3 * v] < 0; }
  const std::vector<int>& free_dofs() const { return m_free_dofs; }

  /// Restrict a full 3n vector to the unknowns.
  VecX restrict(const VecX& full) const;
  /// Same, into an existing vector (no allocation once sized).
  void restrict_into(const VecX& full, VecX& reduced) const;

  private:
  std::vector<int> m_free_index;
  std::vector<int> m_free_dofs;
};

} // namespace elastolearn::fem
