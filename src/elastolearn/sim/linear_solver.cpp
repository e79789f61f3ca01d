#include <elastolearn/core/error.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <cstdlib>
#include <vector>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace elastolearn::sim {

std::string to_string(LinearSolverType type) {
  switch (type) {
  case LinearSolverType::Cholmod: return "cholmod";
  case LinearSolverType::ConjugateGradient: return "cg";
  case LinearSolverType::EigenLdlt: return "eigen-ldlt";
  }
  return "?";
}

LinearSolverType linear_solver_type_from_string(const std::string& name) {
  for (auto t : {LinearSolverType::Cholmod, LinearSolverType::ConjugateGradient, LinearSolverType::EigenLdlt})
    if (to_string(t) == name) return t;
  throw InputError("linear_solver", "unknown linear solver '" + name + "' (valid: cholmod, cg, eigen-ldlt)");
}

// OpenBLAS's thread control, when CHOLMOD runs on OpenBLAS (weak: absent with other BLAS).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace {

/// Below this many unknowns CHOLMOD's supernodes are too small for threaded BLAS to pay; its
/// spinning threads then only steal the cores from the oneTBB element loops (measured: 3× the
/// system time on a 1k-tet bar). Above it, BLAS gets all cores for the factorisation.
constexpr Eigen::Index kThreadedBlasMinUnknowns = 20000;

/// Direct solvers share one implementation (Eigen's wrappers have the same precompute/solve API).
template <typename Factorization, LinearSolverType Type> class DirectSolver final : public LinearSolver {
public:
  void analyze(const fem::SparseMatrix& A) override {
    m_threaded_blas = A.rows() >= kThreadedBlasMinUnknowns;
    m_factor.analyzePattern(A);
  }
  bool factorize(const fem::SparseMatrix& A) override {
    if (Type == LinearSolverType::Cholmod && openblas_set_num_threads && !std::getenv("OPENBLAS_NUM_THREADS"))
      openblas_set_num_threads(m_threaded_blas ? tbb::this_task_arena::max_concurrency() : 1);
    m_factor.factorize(A);
    return m_factor.info() == Eigen::Success;
  }
  bool solve(const VecX& b, VecX& x, double) override {
    x = m_factor.solve(b);
    return m_factor.info() == Eigen::Success && x.allFinite();
  }
  LinearSolverType type() const override { return Type; }

private:
  Factorization m_factor;
  bool m_threaded_blas = false;
};

/// Jacobi-preconditioned CG on the full symmetric matrix. Hand-written rather than Eigen's
/// ConjugateGradient because Eigen parallelises its product only with OpenMP and row-major
/// storage, and because the product (most of CG's time, memory-bound) runs here on a compact
/// copy of A: 3×3 vertex blocks (one row index per 9 values) in single precision, 4.4 bytes per
/// nonzero instead of 9.3, accumulated in double. The float copy only steers the Krylov
/// iteration: on convergence the true residual ‖b − Ax‖ is checked with A in double and CG
/// restarts from x (iterative refinement) until it is ≤ tol·‖b‖, so the tolerance keeps its
/// meaning; should refinement stall (A so ill-conditioned that float rounding dominates), CG
/// continues with the double matrix. y_J = A.col(J)·x (A is symmetric) runs race-free in
/// parallel under oneTBB.
class CgSolver final : public LinearSolver {
public:
  void analyze(const fem::SparseMatrix&) override {}
  bool factorize(const fem::SparseMatrix& A) override {
    m_matrix = &A;
    // The block copy relies on whole-vertex unknown triplets: columns 3J..3J+2 share one row
    // pattern made of whole row triplets (true for SystemMatrix).
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* values = A.valuePtr();
    ELASTOLEARN_CHECK(A.cols() % 3 == 0 && A.isCompressed(), "CG needs whole-vertex unknown triplets");
    const int blocks = static_cast<int>(A.cols() / 3);
    m_block_outer.resize(blocks + 1);
    m_block_outer[0] = 0;
    for (int J = 0; J < blocks; ++J) {
      const int length = outer[3 * J + 1] - outer[3 * J];
      ELASTOLEARN_CHECK(length % 3 == 0 && outer[3 * J + 2] - outer[3 * J + 1] == length &&
                            outer[3 * J + 3] - outer[3 * J + 2] == length,
                        "CG needs vertex triplets with a shared column pattern");
      m_block_outer[J + 1] = m_block_outer[J] + length / 3;
    }
    const int total = m_block_outer[blocks];
    m_block_row.resize(total);
    m_block_values.resize(static_cast<size_t>(total) * 9);
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 512), [&](const tbb::blocked_range<int>& r) {
      for (int J = r.begin(); J < r.end(); ++J) {
        const int c[3] = {outer[3 * J], outer[3 * J + 1], outer[3 * J + 2]};
        for (int t = m_block_outer[J], local = 0; t < m_block_outer[J + 1]; ++t, local += 3) {
          const int row = inner[c[0] + local];
          ELASTOLEARN_CHECK(row % 3 == 0 && inner[c[0] + local + 2] == row + 2,
                            "CG needs whole-vertex row triplets");
          m_block_row[t] = row / 3;
          float* v = m_block_values.data() + 9 * static_cast<size_t>(t);
          for (int i = 0; i < 3; ++i) {
            v[2 * i] = static_cast<float>(values[c[0] + local + i]);
            v[2 * i + 1] = static_cast<float>(values[c[1] + local + i]);
            v[6 + i] = static_cast<float>(values[c[2] + local + i]);
          }
        }
      }
    });
    m_inverse_diagonal = A.diagonal().cwiseInverse();
    return (A.diagonal().array() > 0).all();
  }
  bool solve(const VecX& b, VecX& x, double relative_tolerance) override {
    const Eigen::Index n = b.size();
    m_r.resize(n), m_z.resize(n), m_p.resize(n), m_q.resize(n);
    if (x.size() != n) x.setZero(n);
    const double b_norm = b.norm();
    const double threshold = relative_tolerance * (b_norm > 0 ? b_norm : 1.0);
    const int max_iterations = static_cast<int>(std::max<Eigen::Index>(1000, 2 * n));
    m_iterations = 0;
    bool single = true;
    for (int restart = 0;; ++restart) {
      multiply_double(x, m_q);
      m_r = b - m_q;
      const double residual = m_r.norm();
      if (residual <= threshold) return x.allFinite();
      if (m_iterations >= max_iterations) return false;
      // Refinement normally ends after the first restart; more means float rounding dominates.
      if (restart >= 2) single = false;
      if (!iterate(x, threshold, max_iterations, single)) return false;
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
      if (single) multiply_single(m_p, m_q);
      else multiply_double(m_p, m_q);
      const double pq = m_p.dot(m_q);
      if (!(pq > 0)) return false; // breakdown: not positive definite
      const double alpha = rz / pq;
      x += alpha * m_p;
      m_r -= alpha * m_q;
      if (m_r.norm() <= threshold) return true;
      m_z = m_inverse_diagonal.cwiseProduct(m_r);
      const double rz_next = m_r.dot(m_z);
      m_p = m_z + (rz_next / rz) * m_p;
      rz = rz_next;
    }
    return true; // the caller's true-residual test reports the failure
  }

  /// y = A x with the float block copy: per 3×3 block one index load and 9 multiply-adds, the
  /// first two output rows as one 2-wide vector (see m_block_values' layout).
  void multiply_single(const VecX& x, VecX& y) const {
    using Vec2 = Eigen::Vector2d;
    using Vec2f = Eigen::Vector2f;
    const int blocks = static_cast<int>(m_block_outer.size()) - 1;
    const double* xp = x.data();
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 256), [&](const tbb::blocked_range<int>& r) {
      for (int J = r.begin(); J < r.end(); ++J) {
        Vec2 y01 = Vec2::Zero(), y2 = Vec2::Zero();
        double y2_last = 0;
        for (int t = m_block_outer[J]; t < m_block_outer[J + 1]; ++t) {
          const double* xi = xp + 3 * m_block_row[t];
          const float* v = m_block_values.data() + 9 * static_cast<size_t>(t);
          y01 += Eigen::Map<const Vec2f>(v).cast<double>() * xi[0] +
                 Eigen::Map<const Vec2f>(v + 2).cast<double>() * xi[1] +
                 Eigen::Map<const Vec2f>(v + 4).cast<double>() * xi[2];
          y2 += Eigen::Map<const Vec2f>(v + 6).cast<double>().cwiseProduct(Eigen::Map<const Vec2>(xi));
          y2_last += double(v[8]) * xi[2];
        }
        y[3 * J] = y01[0], y[3 * J + 1] = y01[1], y[3 * J + 2] = y2[0] + y2[1] + y2_last;
      }
    });
  }

  /// y = A x with the double matrix. Columns 3J, 3J+1, 3J+2 share one row pattern: walking them
  /// together loads each row index and x entry once for three multiply-adds.
  void multiply_double(const VecX& x, VecX& y) const {
    const auto& A = *m_matrix;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* values = A.valuePtr();
    const int blocks = static_cast<int>(A.cols() / 3);
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 256), [&](const tbb::blocked_range<int>& r) {
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
  std::vector<int> m_block_outer;     ///< vertex column J → its blocks [outer[J], outer[J+1])
  std::vector<int> m_block_row;       ///< block → vertex row I
  /// block → 9 values: v[2i + k] = A(3I + i, 3J + k) for k = 0, 1, then v[6 + i] = A(3I + i, 3J + 2)
  /// (columns 0 and 1 interleaved, so y_J's first two rows form one 2-wide product).
  std::vector<float> m_block_values;
  VecX m_inverse_diagonal, m_r, m_z, m_p, m_q;
  int m_iterations = 0;
};

} // namespace

std::unique_ptr<LinearSolver> make_linear_solver(LinearSolverType type) {
  switch (type) {
  case LinearSolverType::Cholmod:
    return std::make_unique<DirectSolver<Eigen::CholmodSupernodalLLT<fem::SparseMatrix, Eigen::Upper>,
                                         LinearSolverType::Cholmod>>();
  case LinearSolverType::ConjugateGradient: return std::make_unique<CgSolver>();
  case LinearSolverType::EigenLdlt:
    return std::make_unique<DirectSolver<Eigen::SimplicialLDLT<fem::SparseMatrix, Eigen::Upper>,
                                         LinearSolverType::EigenLdlt>>();
  }
  return nullptr;
}

} // namespace elastolearn::sim
