#include <elastolearn/core/error.hpp>
#include <elastolearn/fem/system_matrix.hpp>

#include <algorithm>
#include <tbb/parallel_for.h>

namespace elastolearn::fem {

namespace {

/// Compressed lists: item → range [offsets[i], offsets[i+1]) of `entries`.
struct Adjacency {
  std::vector<int> offsets, entries;
};

/// Elements in chunks of consecutive entries of an element order, the chunks grouped by colour.
struct ChunkColouring {
  std::vector<int> chunk_offsets, colour_chunks, colour_offsets;
  int colours() const { return static_cast<int>(colour_offsets.size()) - 1; }
};

/// Above this many colours the index order is considered poorly numbered (little parallelism).
constexpr int kMaxIndexOrderColours = 16;

/// Vertex → elements containing it.
Adjacency vertex_elements(const Tets& tets, int num_vertices) {
  Adjacency adj;
  adj.offsets.assign(num_vertices + 1, 0);
  for (Eigen::Index e = 0; e < tets.rows(); ++e)
    for (int a = 0; a < 4; ++a)
      ++adj.offsets[tets(e, a) + 1];
  for (int v = 0; v < num_vertices; ++v)
    adj.offsets[v + 1] += adj.offsets[v];
  adj.entries.resize(adj.offsets[num_vertices]);
  std::vector<int> fill(adj.offsets.begin(), adj.offsets.end() - 1);
  for (Eigen::Index e = 0; e < tets.rows(); ++e)
    for (int a = 0; a < 4; ++a)
      adj.entries[fill[tets(e, a)]++] = static_cast<int>(e);
  return adj;
}

/// Elements in breadth-first order through shared vertices: consecutive runs of this order are
/// compact regions of the mesh whatever the input numbering, so chunks of it have few neighbours.
std::vector<int> breadth_first_elements(const Tets& tets, const Adjacency& vertex_elems) {
  const int m = static_cast<int>(tets.rows());
  std::vector<int> order;
  order.reserve(m);
  std::vector<char> seen(m, 0);
  for (int start = 0; start < m; ++start) {
    if (seen[start])
      continue;
    seen[start] = 1;
    order.push_back(start);
    for (size_t head = order.size() - 1; head < order.size(); ++head) {
      const int e = order[head];
      for (int a = 0; a < 4; ++a) {
        const int v = tets(e, a);
        for (int j = vertex_elems.offsets[v]; j < vertex_elems.offsets[v + 1]; ++j) {
          const int f = vertex_elems.entries[j];
          if (!seen[f])
            seen[f] = 1, order.push_back(f);
        }
      }
    }
  }
  return order;
}

/// Chunk `order` and colour the chunks greedily (chunks of one colour share no free vertex).
ChunkColouring colour_chunks(const Tets& tets, const DofMap& dofs, const Adjacency& vertex_elems,
    const std::vector<int>& order);

} // namespace

SystemMatrix::SystemMatrix(const Tets& tets, const DofMap& dofs) {
  const int n = dofs.num_free();
  const int m = static_cast<int>(tets.rows());
  const int num_vertices = dofs.num_dofs() / 3;
  // Column adjacency of free dofs through shared tets.
  std::vector<std::vector<int>> columns(n);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) {
        const int col = dofs.free_index(3 * tets(e, a) + i);
        if (col < 0)
          continue;
        for (int b = 0; b < 4; ++b)
          for (int k = 0; k < 3; ++k) {
            const int row = dofs.free_index(3 * tets(e, b) + k);
            if (row >= 0)
              columns[col].push_back(row);
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
  for (int c = 0; c < n; ++c)
    std::copy(columns[c].begin(), columns[c].end(), inner.begin() + outer[c]);
  std::vector<double> zeros(nnz, 0.0);
  m_matrix = Eigen::Map<const SparseMatrix>(n, n, nnz, outer.data(), inner.data(), zeros.data());
  m_matrix.makeCompressed();

  auto slot = [&](int row, int col) {
    const int* begin = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col];
    const int* end = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - m_matrix.innerIndexPtr());
  };
  m_diagonal_slot.resize(n);
  for (int c = 0; c < n; ++c)
    m_diagonal_slot[c] = slot(c, c);

  // Element slots, checking the whole-vertex layout the direct assembly relies on.
  const int* col_start = m_matrix.outerIndexPtr();
  m_element_slots.assign(static_cast<size_t>(m) * 16, -1);
  m_element_column_length.assign(static_cast<size_t>(m) * 4, 0);
  for (int e = 0; e < m; ++e)
    for (int b = 0; b < 4; ++b) {
      const int cb = dofs.free_index(3 * tets(e, b));
      if (cb < 0)
        continue;
      const int length = col_start[cb + 1] - col_start[cb];
      m_element_column_length[4 * e + b] = length;
      for (int a = 0; a < 4; ++a) {
        const int ra = dofs.free_index(3 * tets(e, a));
        if (ra < 0)
          continue;
        const int base = slot(ra, cb);
        m_element_slots[16 * e + 4 * b + a] = base;
        for (int k = 0; k < 3; ++k)
          for (int i = 0; i < 3; ++i)
            ELASTOLEARN_CHECK(dofs.free_index(3 * tets(e, a) + i) == ra + i
                    && dofs.free_index(3 * tets(e, b) + k) == cb + k
                    && slot(ra + i, cb + k) == base + k * length + i,
                "SystemMatrix needs whole free vertices with consecutive dofs");
      }
    }

  // Chunks of consecutive elements, greedily coloured so that chunks of one colour share no free
  // vertex. Index order keeps the element data streaming and, for the spatially coherent
  // numbering of generated meshes (box bars, TetGen's Hilbert-sorted output), gives compact
  // chunks and a handful of colours; a poorly numbered mesh (too many colours) is chunked in
  // breadth-first order instead. The chunk size depends on m only (not on the thread count), so
  // the summation order, hence the values, is the same for any thread count.
  const Adjacency vertex_elems = vertex_elements(tets, num_vertices);
  m_chunk_elements.resize(m);
  for (int e = 0; e < m; ++e)
    m_chunk_elements[e] = e;
  ChunkColouring colouring = colour_chunks(tets, dofs, vertex_elems, m_chunk_elements);
  if (colouring.colours() > kMaxIndexOrderColours) {
    m_chunk_elements = breadth_first_elements(tets, vertex_elems);
    colouring = colour_chunks(tets, dofs, vertex_elems, m_chunk_elements);
  }
  m_chunk_offsets = std::move(colouring.chunk_offsets);
  m_colour_chunks = std::move(colouring.colour_chunks);
  m_colour_offsets = std::move(colouring.colour_offsets);
}

namespace {

ChunkColouring colour_chunks(const Tets& tets, const DofMap& dofs, const Adjacency& vertex_elems,
    const std::vector<int>& order) {
  const int m = static_cast<int>(tets.rows());
  ChunkColouring out;
  const int chunk_size = std::clamp(m / 64, 16, 512);
  const int chunks = (m + chunk_size - 1) / chunk_size;
  out.chunk_offsets.resize(chunks + 1);
  for (int c = 0; c <= chunks; ++c)
    out.chunk_offsets[c] = std::min(c * chunk_size, m);
  std::vector<int> chunk_of(m);
  for (int c = 0; c < chunks; ++c)
    for (int j = out.chunk_offsets[c]; j < out.chunk_offsets[c + 1]; ++j)
      chunk_of[order[j]] = c;
  std::vector<int> colour(chunks, -1), mark;
  int colours = 0;
  for (int c = 0; c < chunks; ++c) {
    for (int j = out.chunk_offsets[c]; j < out.chunk_offsets[c + 1]; ++j)
      for (int a = 0; a < 4; ++a) {
        const int v = tets(order[j], a);
        if (dofs.is_prescribed_vertex(v))
          continue;
        for (int t = vertex_elems.offsets[v]; t < vertex_elems.offsets[v + 1]; ++t) {
          const int other = colour[chunk_of[vertex_elems.entries[t]]];
          if (other >= 0)
            mark[other] = c;
        }
      }
    int k = 0;
    while (k < colours && mark[k] == c)
      ++k;
    if (k == colours)
      ++colours, mark.push_back(-1);
    colour[c] = k;
  }
  out.colour_offsets.assign(colours + 1, 0);
  for (int c = 0; c < chunks; ++c)
    ++out.colour_offsets[colour[c] + 1];
  for (int k = 0; k < colours; ++k)
    out.colour_offsets[k + 1] += out.colour_offsets[k];
  out.colour_chunks.resize(chunks);
  std::vector<int> fill(out.colour_offsets.begin(), out.colour_offsets.end() - 1);
  for (int c = 0; c < chunks; ++c)
    out.colour_chunks[fill[colour[c]]++] = c;
  return out;
}

} // namespace

void SystemMatrix::set_zero() {
  std::fill_n(m_matrix.valuePtr(), m_matrix.nonZeros(), 0.0);
}

void SystemMatrix::add_elements(const std::function<void(int e, Mat12& K)>& element) {
  double* values = m_matrix.valuePtr();
  const int colours = static_cast<int>(m_colour_offsets.size()) - 1;
  for (int k = 0; k < colours; ++k)
    tbb::parallel_for(tbb::blocked_range<int>(m_colour_offsets[k], m_colour_offsets[k + 1], 1),
        [&](const tbb::blocked_range<int>& r) {
          Mat12 K;
          for (int c = r.begin(); c < r.end(); ++c) {
            const int chunk = m_colour_chunks[c];
            for (int j = m_chunk_offsets[chunk]; j < m_chunk_offsets[chunk + 1]; ++j) {
              const int e = m_chunk_elements[j];
              element(e, K);
              const int* slots = m_element_slots.data() + 16 * static_cast<size_t>(e);
              const int* lengths = m_element_column_length.data() + 4 * static_cast<size_t>(e);
              for (int b = 0; b < 4; ++b)
                for (int a = 0; a < 4; ++a) {
                  const int base = slots[4 * b + a];
                  if (base < 0)
                    continue;
                  for (int kk = 0; kk < 3; ++kk) {
                    double* out = values + base + kk * lengths[b];
                    const double* in = K.data() + (3 * b + kk) * 12 + 3 * a;
                    out[0] += in[0], out[1] += in[1], out[2] += in[2];
                  }
                }
            }
          }
        });
}

void SystemMatrix::add_element_blocks(const std::vector<double>& element_blocks, double scale) {
  ELASTOLEARN_CHECK(element_blocks.size() == static_cast<size_t>(num_elements()) * 144,
      "element buffer size does not match the mesh");
  add_elements([&](int e, Mat12& K) {
    K = scale * Eigen::Map<const Mat12>(element_blocks.data() + 144 * static_cast<size_t>(e));
  });
}

void SystemMatrix::add_diagonal(const VecX& reduced_diagonal, double scale) {
  double* values = m_matrix.valuePtr();
  for (int i = 0; i < size(); ++i)
    values[m_diagonal_slot[i]] += scale * reduced_diagonal[i];
}

void SystemMatrix::add_values(const VecX& other, double scale) {
  Eigen::Map<VecX>(m_matrix.valuePtr(), m_matrix.nonZeros()) += scale * other;
}

VecX SystemMatrix::values() const {
  return Eigen::Map<const VecX>(m_matrix.valuePtr(), m_matrix.nonZeros());
}

} // namespace elastolearn::fem
