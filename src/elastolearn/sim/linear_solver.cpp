#include <elastolearn/core/error.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstdlib>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <vector>

namespace elastolearn::sim {

std::string to_string(LinearSolverType type) {
  switch (type) {
  case LinearSolverType::Cholmod:
    return "cholmod";
  case LinearSolverType::ConjugateGradient:
    return "cg";
  case LinearSolverType::EigenLdlt:
    return "eigen-ldlt";
  }
  return "?";
}

LinearSolverType linear_solver_type_from_string(const std::string& name) {
  for (auto t : { LinearSolverType::Cholmod, LinearSolverType::ConjugateGradient,
           LinearSolverType::EigenLdlt })
    if (to_string(t) == name)
      return t;
  throw InputError(
      "linear_solver", "unknown linear solver '" + name + "' (valid: cholmod, cg, eigen-ldlt)");
}

// OpenBLAS's thread control, when CHOLMOD runs on OpenBLAS (weak: absent with other BLAS).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

bool LinearSolver::solve(const MatX& b, MatX& x, double relative_tolerance) {
  x.setZero(b.rows(), b.cols());
  VecX column;
  for (Eigen::Index j = 0; j < b.cols(); ++j) {
    column.setZero(b.rows());
    if (!solve(VecX(b.col(j)), column, relative_tolerance))
      return false;
    x.col(j) = column;
  }
  return true;
}

namespace {

/// Below this many unknowns CHOLMOD's supernodes are too small for threaded BLAS to pay; its
/// spinning threads then only steal the cores from the oneTBB element loops (measured: 3× the
/// system time on a 1k-tet bar). Above it, BLAS gets all cores for the factorisation.
constexpr Eigen::Index kThreadedBlasMinUnknowns = 20000;

/// Direct solvers share one implementation (Eigen's wrappers have the same precompute/solve API).
template <typename Factorization, LinearSolverType Type>
class DirectSolver final : public LinearSolver {
  public:
  DirectSolver() {
    // A matrix that is not positive definite is a result (factorize returns false and the caller
    // reports it), not something for CHOLMOD to print on stderr.
    if constexpr (Type == LinearSolverType::Cholmod)
      m_factor.cholmod().print = 0;
  }
  void analyze(const fem::SparseMatrix& A) override {
    m_threaded_blas = A.rows() >= kThreadedBlasMinUnknowns;
    m_factor.analyzePattern(A);
  }
  bool factorize(const fem::SparseMatrix& A) override {
    if (Type == LinearSolverType::Cholmod && openblas_set_num_threads
        && !std::getenv("OPENBLAS_NUM_THREADS")) {
      // Set only on a change: OpenBLAS's setting is global and not thread-safe, and two solvers
      // of the same system can factorise at once (sim::RunAhead beside the forward fit's).
      static std::atomic<int> s_blas_threads { 0 };
      const int threads = m_threaded_blas ? tbb::this_task_arena::max_concurrency() : 1;
      if (s_blas_threads.exchange(threads) != threads)
        openblas_set_num_threads(threads);
    }
    m_factor.factorize(A);
    return m_factor.info() == Eigen::Success;
  }
  bool solve(const VecX& b, VecX& x, double) override {
    x = m_factor.solve(b);
    return m_factor.info() == Eigen::Success && x.allFinite();
  }
  bool solve(const MatX& b, MatX& x, double) override {
    x = m_factor.solve(b);
    return m_factor.info() == Eigen::Success && x.allFinite();
  }
  LinearSolverType type() const override { return Type; }

  private:
  Factorization m_factor;
  bool m_threaded_blas = false;
};

/// The float product's vertex-column ranges (see CgSolver) are at least this wide: a range's spill
/// spans about the matrix's block bandwidth (~800 vertex rows for the 53k-tet bar), so wider ranges
/// keep the spill traffic small next to the range's blocks (measured, 53k bar, one thread: 8 ranges
/// cost 5 % more product time than 1, 16 ranges 10 %).
constexpr int kMinRangeColumns = 1024;
constexpr int kMaxRanges = 64;

/// Jacobi-preconditioned CG. Hand-written rather than Eigen's ConjugateGradient because Eigen
/// parallelises its product only with OpenMP and row-major storage, and because the product (most
/// of CG's time, memory-bound) runs here on a compact copy of A: its upper block triangle only
/// (3×3 vertex blocks A_IJ with I ≤ J, one row index per 9 values) in single precision,
/// accumulated in double: about 2.4 bytes per nonzero of A, against 9.3 for the double matrix
/// (multiply_double) and 4.4 for a float copy of both triangles. Each stored off-diagonal block
/// serves both triangles: y_J += A_IJᵀ x_I (gathered in registers along column J) and
/// y_I += A_IJ x_J (scattered). The float copy only steers the Krylov iteration: on convergence
/// the true residual ‖b − Ax‖ is checked with A in double and CG restarts from x (iterative
/// refinement) until it is ≤ tol·‖b‖, so the tolerance keeps its meaning; should refinement
/// stall (A so ill-conditioned that float rounding dominates), CG continues with the double
/// matrix.
/// Parallel product without races or atomics: the vertex columns are cut into a power-of-two
/// number of contiguous ranges of about equal work, fixed by the pattern (not by the thread
/// count). A range processes its columns in increasing order and writes y for its own rows; its
/// scatter into rows below its first column goes to its own spill buffer, and after the parallel
/// pass each range's rows add the later ranges' spills in range order. The summation order is
/// thus fixed: results are bit-identical for any thread count and schedule (the learning loop's
/// resume relies on it).
class CgSolver final : public LinearSolver {
  public:
  /// The block pattern, the column ranges and their spill buffers (allocated here, once).
  void analyze(const fem::SparseMatrix& A) override {
    // The block copy relies on whole-vertex unknown triplets: columns 3J..3J+2 share one row
    // pattern made of whole row triplets (true for SystemMatrix).
    ELASTOLEARN_CHECK(A.cols() % 3 == 0 && A.rows() == A.cols() && A.isCompressed(),
        "CG needs whole-vertex unknown triplets");
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const int columns = static_cast<int>(A.cols() / 3);
    m_block_outer.assign(columns + 1, 0);
    for (int J = 0; J < columns; ++J) {
      const int length = outer[3 * J + 1] - outer[3 * J];
      ELASTOLEARN_CHECK(length % 3 == 0 && outer[3 * J + 2] - outer[3 * J + 1] == length
              && outer[3 * J + 3] - outer[3 * J + 2] == length,
          "CG needs vertex triplets with a shared column pattern");
      int upper = 0;
      for (int k = outer[3 * J]; k < outer[3 * J + 1]; k += 3) {
        ELASTOLEARN_CHECK(inner[k] % 3 == 0 && inner[k + 2] == inner[k] + 2,
            "CG needs whole-vertex row triplets");
        upper += inner[k] / 3 < J;
      }
      m_block_outer[J + 1] = m_block_outer[J] + upper;
    }
    m_block_row.resize(m_block_outer[columns]);
    for (int J = 0; J < columns; ++J)
      for (int k = outer[3 * J], t = m_block_outer[J]; k < outer[3 * J + 1]; k += 3)
        if (inner[k] / 3 < J)
          m_block_row[t++] = inner[k] / 3;
    m_block_values.resize(9 * m_block_row.size());
    m_diagonal_values.assign(9 * static_cast<size_t>(columns), 0.0f);

    int ranges = 1;
    while (2 * ranges <= std::min(kMaxRanges, columns / kMinRangeColumns))
      ranges *= 2;
    // Balance the stored blocks (off-diagonal ones before column J, plus J diagonal ones).
    const long total = m_block_outer[columns] + long(columns);
    m_range_begin.assign(ranges + 1, columns);
    m_range_begin[0] = 0;
    for (int p = 1, J = 0; p < ranges; ++p) {
      while (J < columns && m_block_outer[J] + long(J) < total * p / ranges)
        ++J;
      m_range_begin[p] = J;
    }
    m_range_low.resize(ranges);
    m_spill_offset.assign(ranges + 1, 0);
    for (int p = 0; p < ranges; ++p) {
      const int first = m_range_begin[p];
      int low = first;
      for (int t = m_block_outer[first]; t < m_block_outer[m_range_begin[p + 1]]; ++t)
        low = std::min(low, m_block_row[t]);
      m_range_low[p] = low;
      m_spill_offset[p + 1] = m_spill_offset[p] + 3 * (first - m_range_low[p]);
    }
    m_spill.resize(m_spill_offset[ranges]);
    m_analyzed_nonzeros = A.nonZeros();
  }

  bool factorize(const fem::SparseMatrix& A) override {
    if (A.cols() != 3 * (static_cast<Eigen::Index>(m_block_outer.size()) - 1)
        || A.nonZeros() != m_analyzed_nonzeros)
      analyze(A);
    m_matrix = &A;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* values = A.valuePtr();
    const int columns = static_cast<int>(A.cols() / 3);
    m_inverse_diagonal.setZero(
        A.cols()); // stays 0 (not positive) where the pattern lacks a diagonal
    tbb::parallel_for(
        tbb::blocked_range<int>(0, columns, 512), [&](const tbb::blocked_range<int>& r) {
          for (int J = r.begin(); J < r.end(); ++J) {
            const int c[3] = { outer[3 * J], outer[3 * J + 1], outer[3 * J + 2] };
            for (int local = 0, t = m_block_outer[J]; c[0] + local < c[1]; local += 3) {
              const int I = inner[c[0] + local] / 3;
              if (I > J)
                continue;
              assert(I == J || m_block_row[t] == I); // the pattern analyze() saw
              float* v = I == J ? m_diagonal_values.data() + 9 * static_cast<size_t>(J)
                                : m_block_values.data() + 9 * static_cast<size_t>(t++);
              for (int k = 0; k < 3; ++k) {
                v[2 * k] = static_cast<float>(values[c[k] + local]);
                v[2 * k + 1] = static_cast<float>(values[c[k] + local + 1]);
                v[6 + k] = static_cast<float>(values[c[k] + local + 2]);
              }
              if (I == J)
                for (int k = 0; k < 3; ++k) {
                  const double diagonal = values[c[k] + local + k];
                  m_inverse_diagonal[3 * J + k] = diagonal > 0 ? 1 / diagonal : 0.0;
                }
            }
          }
        });
    return (m_inverse_diagonal.array() > 0).all();
  }
  bool solve(const VecX& b, VecX& x, double relative_tolerance) override {
    const Eigen::Index n = b.size();
    m_r.resize(n), m_z.resize(n), m_p.resize(n), m_q.resize(n);
    if (x.size() != n)
      x.setZero(n);
    const double b_norm = b.norm();
    const double threshold = relative_tolerance * (b_norm > 0 ? b_norm : 1.0);
    const int max_iterations = static_cast<int>(std::max<Eigen::Index>(1000, 2 * n));
    m_iterations = 0;
    bool single = true;
    for (int restart = 0;; ++restart) {
      multiply_double(x, m_q);
      m_r = b - m_q;
      const double residual = m_r.norm();
      if (residual <= threshold)
        return x.allFinite();
      if (m_iterations >= max_iterations)
        return false;
      // Refinement normally ends after the first restart; more means float rounding dominates.
      if (restart >= 2)
        single = false;
      if (!iterate(x, threshold, max_iterations, single))
        return false;
    }
  }
  int last_iterations() const override { return m_iterations; }
  LinearSolverType type() const override { return LinearSolverType::ConjugateGradient; }

  private:
  /// Preconditioned CG from x with m_r = b − A x, until the recurrence residual is ≤ threshold.
  /// Returns false on breakdown (A not positive definite) or when out of iterations.
  bool iterate(VecX& x, double threshold, int max_iterations, bool single) {
    m_z = m_inverse_diagonal.cwiseProduct(m_r);
    m_p = m_z;
    double rz = m_r.dot(m_z);
    while (m_iterations < max_iterations) {
      ++m_iterations;
      if (single)
        multiply_single(m_p, m_q);
      else
        multiply_double(m_p, m_q);
      const double pq = m_p.dot(m_q);
      if (!(pq > 0))
        return false; // breakdown: not positive definite
      const double alpha = rz / pq;
      x += alpha * m_p;
      m_r -= alpha * m_q;
      if (m_r.norm() <= threshold)
        return true;
      m_z = m_inverse_diagonal.cwiseProduct(m_r);
      const double rz_next = m_r.dot(m_z);
      m_p = m_z + (rz_next / rz) * m_p;
      rz = rz_next;
    }
    return true; // the caller's true-residual test reports the failure
  }

  /// y = A x with the float upper block triangle (see the class comment); y must not alias x.
  void multiply_single(const VecX& x, VecX& y) {
    const int ranges = static_cast<int>(m_range_low.size());
    if (ranges == 1)
      return multiply_range(0, x.data(), y.data());
    tbb::parallel_for(tbb::blocked_range<int>(0, ranges, 1), [&](const tbb::blocked_range<int>& r) {
      for (int p = r.begin(); p < r.end(); ++p)
        multiply_range(p, x.data(), y.data());
    });
    // Range r's rows take the spills of the ranges after it, in range order.
    tbb::parallel_for(
        tbb::blocked_range<int>(0, ranges - 1, 1), [&](const tbb::blocked_range<int>& r) {
          for (int target = r.begin(); target < r.end(); ++target)
            for (int p = target + 1; p < ranges; ++p) {
              const int begin = std::max(m_range_low[p], m_range_begin[target]);
              const int end = std::min(m_range_begin[p], m_range_begin[target + 1]);
              if (begin >= end)
                continue;
              const double* spill
                  = m_spill.data() + m_spill_offset[p] + 3 * (begin - m_range_low[p]);
              for (int i = 3 * begin; i < 3 * end; ++i)
                y[i] += *spill++;
            }
        });
  }

  /// Columns of range p: y_J for its own rows (assigned when column J is reached, as the scatter
  /// of column J' only reaches rows I < J'), and the scatter into rows below the range into the
  /// range's spill. Per off-diagonal block (layout: m_block_values): the gather y_J += Bᵀ x_I as
  /// three 2-wide element-wise products summed once per column, and the scatter y_I += B x_J with
  /// its first two rows as one 2-wide vector.
  void multiply_range(int p, const double* x, double* y) {
    using Vec2 = Eigen::Vector2d;
    using Map2f = Eigen::Map<const Eigen::Vector2f>;
    const int first = m_range_begin[p], low = m_range_low[p];
    double* spill = m_spill.data() + m_spill_offset[p];
    std::fill(spill, spill + 3 * (first - low), 0.0);
    const int* outer = m_block_outer.data();
    const int* rows = m_block_row.data();
    const float* values = m_block_values.data();
    for (int J = first; J < m_range_begin[p + 1]; ++J) {
      const Vec2 xJ01 = Eigen::Map<const Vec2>(x + 3 * J);
      const double xJ0 = x[3 * J], xJ1 = x[3 * J + 1], xJ2 = x[3 * J + 2];
      // Diagonal block: y_J = A_JJ x_J.
      const float* d = m_diagonal_values.data() + 9 * static_cast<size_t>(J);
      Vec2 y01 = Map2f(d).cast<double>() * xJ0 + Map2f(d + 2).cast<double>() * xJ1
          + Map2f(d + 4).cast<double>() * xJ2;
      const Vec2 d2 = Map2f(d + 6).cast<double>().cwiseProduct(xJ01);
      double y2 = d2[0] + d2[1] + double(d[8]) * xJ2;
      Vec2 g0 = Vec2::Zero(), g1 = Vec2::Zero(), g2 = Vec2::Zero();
      for (int t = outer[J], end = outer[J + 1]; t < end; ++t) {
        const int I = rows[t];
        const float* v = values + 9 * static_cast<size_t>(t);
        const Vec2 b0 = Map2f(v).cast<double>(), b1 = Map2f(v + 2).cast<double>(),
                   b2 = Map2f(v + 4).cast<double>();
        const Vec2 b_row2 = Map2f(v + 6).cast<double>();
        const double b22 = v[8];
        const Vec2 xI01 = Eigen::Map<const Vec2>(x + 3 * I);
        const double xI2 = x[3 * I + 2];
        g0 += b0.cwiseProduct(xI01);
        g1 += b1.cwiseProduct(xI01);
        g2 += b2.cwiseProduct(xI01);
        y01 += b_row2 * xI2;
        y2 += b22 * xI2;
        double* yI = I < first ? spill + 3 * (I - low) : y + 3 * I;
        Eigen::Map<Vec2>(yI) += b0 * xJ0 + b1 * xJ1 + b2 * xJ2;
        const Vec2 s2 = b_row2.cwiseProduct(xJ01);
        yI[2] += s2[0] + s2[1] + b22 * xJ2;
      }
      y[3 * J] = y01[0] + (g0[0] + g0[1]);
      y[3 * J + 1] = y01[1] + (g1[0] + g1[1]);
      y[3 * J + 2] = y2 + (g2[0] + g2[1]);
    }
  }

  /// y = A x with the double matrix. Columns 3J, 3J+1, 3J+2 share one row pattern: walking them
  /// together loads each row index and x entry once for three multiply-adds.
  void multiply_double(const VecX& x, VecX& y) const {
    const auto& A = *m_matrix;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* values = A.valuePtr();
    const int blocks = static_cast<int>(A.cols() / 3);
    tbb::parallel_for(
        tbb::blocked_range<int>(0, blocks, 256), [&](const tbb::blocked_range<int>& r) {
          for (int J = r.begin(); J < r.end(); ++J) {
            const int c0 = outer[3 * J], c1 = outer[3 * J + 1], c2 = outer[3 * J + 2];
            const int length = c1 - c0;
            double y0 = 0, y1 = 0, y2 = 0;
            for (int k = 0; k < length; ++k) {
              const double xk = x[inner[c0 + k]];
              y0 += values[c0 + k] * xk;
              y1 += values[c1 + k] * xk;
              y2 += values[c2 + k] * xk;
            }
            y[3 * J] = y0, y[3 * J + 1] = y1, y[3 * J + 2] = y2;
          }
        });
  }

  const fem::SparseMatrix* m_matrix = nullptr;
  Eigen::Index m_analyzed_nonzeros = -1;
  std::vector<int>
      m_block_outer; ///< vertex column J → its off-diagonal blocks [outer[J], outer[J+1])
  std::vector<int> m_block_row; ///< off-diagonal block → vertex row I (< J)
  /// Block A_IJ → 9 values: v[2k + i] = A(3I + i, 3J + k) for i = 0, 1, then v[6 + k] = A(3I + 2,
  /// 3J + k) (the first two rows of each column side by side: 2-wide vectors for both products).
  std::vector<float> m_block_values;
  std::vector<float> m_diagonal_values; ///< vertex J → A_JJ, same layout
  std::vector<int> m_range_begin; ///< range p → its vertex columns [begin[p], begin[p+1])
  std::vector<int> m_range_low; ///< range p → lowest row it touches (≤ begin[p])
  std::vector<int> m_spill_offset; ///< range p → its spill (rows [low[p], begin[p])) in m_spill
  std::vector<double> m_spill;
  VecX m_inverse_diagonal, m_r, m_z, m_p, m_q;
  int m_iterations = 0;
};

} // namespace

std::unique_ptr<LinearSolver> make_linear_solver(LinearSolverType type) {
  switch (type) {
  case LinearSolverType::Cholmod:
    return std::make_unique<DirectSolver<
        Eigen::CholmodSupernodalLLT<fem::SparseMatrix, Eigen::Upper>, LinearSolverType::Cholmod>>();
  case LinearSolverType::ConjugateGradient:
    return std::make_unique<CgSolver>();
  case LinearSolverType::EigenLdlt:
    return std::make_unique<DirectSolver<Eigen::SimplicialLDLT<fem::SparseMatrix, Eigen::Upper>,
        LinearSolverType::EigenLdlt>>();
  }
  return nullptr;
}

} // namespace elastolearn::sim
