#pragma once
/// \file The sparse system matrix over the unknowns, with its sparsity pattern built once per
/// scene. Element matrices are written per element into a buffer (in parallel, no locks) and
/// gathered per nonzero (in parallel, deterministic order), so assembly allocates nothing and
/// gives bit-identical results for any thread count.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/dof_map.hpp>

#include <Eigen/SparseCore>
#include <vector>

namespace elastolearn::fem {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Full (both triangles) symmetric matrix over the free dofs of a tet mesh.
class SystemMatrix {
public:
  SystemMatrix() = default;
  /// Build the pattern: every pair of free dofs sharing a tet. O(nnz), once per scene.
  SystemMatrix(const Tets& tets, const DofMap& dofs);

  const SparseMatrix& matrix() const { return m_matrix; }
  int size() const { return static_cast<int>(m_matrix.rows()); }
  long nonzeros() const { return m_matrix.nonZeros(); }

  void set_zero();
  /// values += scale · (gather of the per-element 12×12 blocks in `element_blocks`,
  /// m·144 doubles, element e's block column-major at offset 144 e). Parallel over nonzeros.
  void add_element_blocks(const std::vector<double>& element_blocks, double scale = 1.0);
  /// Add scale · `reduced_diagonal[i]` to diagonal entry i (i indexes the free dofs).
  void add_diagonal(const VecX& reduced_diagonal, double scale = 1.0);
  /// values += scale · other (same pattern, e.g. a precomputed consistent mass).
  void add_values(const VecX& values, double scale = 1.0);
  /// The current values as a vector (to cache a constant matrix such as the consistent mass).
  VecX values() const;

private:
  SparseMatrix m_matrix;
  std::vector<int> m_diagonal_slot;    ///< free dof → position of its diagonal in valuePtr
  std::vector<int> m_gather_offsets;   ///< nnz + 1
  std::vector<int> m_gather_sources;   ///< indices into the element block buffer
};

} // namespace elastolearn::fem
