#include <elastolearn/fem/system_matrix.hpp>

#include <algorithm>
#include <tbb/parallel_for.h>

namespace elastolearn::fem {

SystemMatrix::SystemMatrix(const Tets& tets, const DofMap& dofs) {
  const int n = dofs.num_free();
  const int m = static_cast<int>(tets.rows());
  // Column adjacency of free dofs through shared tets.
  std::vector<std::vector<int>> columns(n);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) {
        const int col = dofs.free_index(3 * tets(e, a) + i);
        if (col < 0) continue;
        for (int b = 0; b < 4; ++b)
          for (int k = 0; k < 3; ++k) {
            const int row = dofs.free_index(3 * tets(e, b) + k);
            if (row >= 0) columns[col].push_back(row);
          }
      }
  std::vector<int> outer(n + 1, 0);
  for (int c = 0; c < n; ++c) {
    auto& rows = columns[c];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    outer[c + 1] = outer[c] + static_cast<int>(rows.size());
  }
  const int nnz = outer[n];
  std::vector<int> inner(nnz);
  for (int c = 0; c < n; ++c) std::copy(columns[c].begin(), columns[c].end(), inner.begin() + outer[c]);
  std::vector<double> zeros(nnz, 0.0);
  m_matrix = Eigen::Map<const SparseMatrix>(n, n, nnz, outer.data(), inner.data(), zeros.data());
  m_matrix.makeCompressed();

  auto slot = [&](int row, int col) {
    const int* begin = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col];
    const int* end = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - m_matrix.innerIndexPtr());
  };
  m_diagonal_slot.resize(n);
  for (int c = 0; c < n; ++c) m_diagonal_slot[c] = slot(c, c);

  // Gather lists: for every nonzero, the element-buffer entries that land on it.
  std::vector<int> counts(nnz + 1, 0);
  std::vector<int> target(static_cast<size_t>(m) * 144, -1);
  for (int e = 0; e < m; ++e)
    for (int b = 0; b < 4; ++b)
      for (int k = 0; k < 3; ++k) {
        const int col = dofs.free_index(3 * tets(e, b) + k);
        if (col < 0) continue;
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) {
            const int row = dofs.free_index(3 * tets(e, a) + i);
            if (row < 0) continue;
            const int s = slot(row, col);
            target[static_cast<size_t>(e) * 144 + (3 * b + k) * 12 + (3 * a + i)] = s;
            ++counts[s + 1];
          }
      }
  for (int s = 0; s < nnz; ++s) counts[s + 1] += counts[s];
  m_gather_offsets = counts;
  m_gather_sources.resize(counts[nnz]);
  std::vector<int> fill(counts.begin(), counts.end() - 1);
  for (size_t src = 0; src < target.size(); ++src)
    if (target[src] >= 0) m_gather_sources[fill[target[src]]++] = static_cast<int>(src);
}

void SystemMatrix::set_zero() {
  std::fill_n(m_matrix.valuePtr(), m_matrix.nonZeros(), 0.0);
}

void SystemMatrix::add_element_blocks(const std::vector<double>& element_blocks, double scale) {
  double* values = m_matrix.valuePtr();
  const int nnz = static_cast<int>(m_matrix.nonZeros());
  tbb::parallel_for(tbb::blocked_range<int>(0, nnz, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int s = r.begin(); s < r.end(); ++s) {
      double sum = 0;
      for (int j = m_gather_offsets[s]; j < m_gather_offsets[s + 1]; ++j)
        sum += element_blocks[m_gather_sources[j]];
      values[s] += scale * sum;
    }
  });
}

void SystemMatrix::add_diagonal(const VecX& reduced_diagonal, double scale) {
  double* values = m_matrix.valuePtr();
  for (int i = 0; i < size(); ++i) values[m_diagonal_slot[i]] += scale * reduced_diagonal[i];
}

void SystemMatrix::add_values(const VecX& other, double scale) {
  Eigen::Map<VecX>(m_matrix.valuePtr(), m_matrix.nonZeros()) += scale * other;
}

VecX SystemMatrix::values() const {
  return Eigen::Map<const VecX>(m_matrix.valuePtr(), m_matrix.nonZeros());
}

} // namespace elastolearn::fem
