#include <elastolearn/core/error.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <cstdlib>
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
/// storage; here y_i = A.col(i)·x (A is symmetric) runs race-free in parallel under oneTBB, and
/// the product is most of CG's time. Convergence test as Eigen's: ‖b − Ax‖ ≤ tol·‖b‖.
class CgSolver final : public LinearSolver {
public:
  void analyze(const fem::SparseMatrix&) override {}
  bool factorize(const fem::SparseMatrix& A) override {
    m_matrix = &A;
    // multiply() relies on vertex triplets sharing their column pattern (true for SystemMatrix).
    const int* outer = A.outerIndexPtr();
    ELASTOLEARN_CHECK(A.cols() % 3 == 0, "CG needs whole-vertex unknown triplets");
    for (Eigen::Index J = 0; J < A.cols() / 3; ++J)
      ELASTOLEARN_CHECK(outer[3 * J + 1] - outer[3 * J] == outer[3 * J + 2] - outer[3 * J + 1] &&
                            outer[3 * J + 2] - outer[3 * J + 1] == outer[3 * J + 3] - outer[3 * J + 2],
                        "CG needs vertex triplets with a shared column pattern");
    m_inverse_diagonal = A.diagonal().cwiseInverse();
    return (A.diagonal().array() > 0).all();
  }
  bool solve(const VecX& b, VecX& x, double relative_tolerance) override {
    const Eigen::Index n = b.size();
    m_r.resize(n), m_z.resize(n), m_p.resize(n), m_q.resize(n);
    if (x.size() != n) x.setZero(n);
    multiply(x, m_q);
    m_r = b - m_q;
    const double b_norm = b.norm();
    const double threshold = relative_tolerance * (b_norm > 0 ? b_norm : 1.0);
    m_iterations = 0;
    if (m_r.norm() <= threshold) return true;
    m_z = m_inverse_diagonal.cwiseProduct(m_r);
    m_p = m_z;
    double rz = m_r.dot(m_z);
    const int max_iterations = static_cast<int>(std::max<Eigen::Index>(1000, 2 * n));
    while (m_iterations < max_iterations) {
      ++m_iterations;
      multiply(m_p, m_q);
      const double pq = m_p.dot(m_q);
      if (!(pq > 0)) return false; // breakdown: not positive definite
      const double alpha = rz / pq;
      x += alpha * m_p;
      m_r -= alpha * m_q;
      if (m_r.norm() <= threshold) return x.allFinite();
      m_z = m_inverse_diagonal.cwiseProduct(m_r);
      const double rz_next = m_r.dot(m_z);
      m_p = m_z + (rz_next / rz) * m_p;
      rz = rz_next;
    }
    return false;
  }
  int last_iterations() const override { return m_iterations; }
  LinearSolverType type() const override { return LinearSolverType::ConjugateGradient; }

private:
  /// y = A x. Unknowns come in whole-vertex triplets, so columns 3J, 3J+1, 3J+2 share one row
  /// pattern: walking them together loads each row index and x entry once for three
  /// multiply-adds (measured: the product is ~40 % of all instructions of a CG-based step).
  void multiply(const VecX& x, VecX& y) const {
    const auto& A = *m_matrix;
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* values = A.valuePtr();
    const int blocks = static_cast<int>(A.cols() / 3);
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 512), [&](const tbb::blocked_range<int>& r) {
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
