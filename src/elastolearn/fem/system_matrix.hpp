#pragma once
/// \file The sparse system matrix over the unknowns, with its sparsity pattern built once per
/// scene. Element matrices are added straight into the values (no per-element buffer): elements
/// run in parallel in groups of chunks that share no vertex (a colouring), so assembly takes no
/// locks, allocates nothing and gives bit-identical results for any thread count.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/dof_map.hpp>

#include <Eigen/SparseCore>
#include <functional>
#include <vector>

namespace elastolearn::fem {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Full (both triangles) symmetric matrix over the free dofs of a tet mesh.
class SystemMatrix {
  public:
  SystemMatrix() = default;
  /// Build the pattern: every pair of free dofs sharing a tet, and the element colouring.
  /// O(nnz), once per scene. `dofs` frees or prescribes whole vertices (as DofMap does).
  SystemMatrix(const Tets& tets, const DofMap& dofs);

  const SparseMatrix& matrix() const { return m_matrix; }
  int size() const { return static_cast<int>(m_matrix.rows()); }
  long nonzeros() const { return m_matrix.nonZeros(); }
  /// Number of tets the pattern was built from.
  int num_elements() const { return static_cast<int>(m_element_slots.size() / 16); }

  void set_zero();
  /// values += K_e for every element e of the tets the pattern was built from, where
  /// `element(e, K)` writes element e's 12×12 matrix (dofs x0,y0,z0,x1,…; all 144 entries are
  /// added) into K. `element` is called concurrently for elements
  /// that share no vertex and must be thread-safe across different e. Rows and columns of
  /// prescribed vertices are dropped.
  void add_elements(const std::function<void(int e, Mat12& K)>& element);
  /// values += scale · (the per-element 12×12 blocks in `element_blocks`, m·144 doubles,
  /// element e's block column-major at offset 144 e).
  void add_element_blocks(const std::vector<double>& element_blocks, double scale = 1.0);
  /// Add scale · `reduced_diagonal[i]` to diagonal entry i (i indexes the free dofs).
  void add_diagonal(const VecX& reduced_diagonal, double scale = 1.0);
  /// values += scale · other (same pattern, e.g. a precomputed consistent mass).
  void add_values(const VecX& values, double scale = 1.0);
  /// The current values as a vector (to cache a constant matrix such as the consistent mass).
  VecX values() const;

  private:
  SparseMatrix m_matrix;
  std::vector<int> m_diagonal_slot; ///< free dof → position of its diagonal in valuePtr
  /// Per element, 16 entries (a, b) → position in valuePtr of entry (row 3a', col 3b') for its
  /// vertices' free triplets a', b' (−1 if either is prescribed); entry (3a'+i, 3b'+k) is at
  /// that + k·(column length of 3b') + i, since a vertex's three columns share one pattern.
  std::vector<int> m_element_slots;
  std::vector<int> m_element_column_length; ///< per element and vertex b: length of column 3b'
  std::vector<int> m_chunk_elements; ///< elements in chunk order
  std::vector<int> m_chunk_offsets; ///< chunk → range in m_chunk_elements
  std::vector<int> m_colour_chunks; ///< chunks grouped by colour
  std::vector<int> m_colour_offsets; ///< colour → range in m_colour_chunks
};

} // namespace elastolearn::fem
