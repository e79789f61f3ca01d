#include <elastolearn/core/error.hpp>
#include <elastolearn/sim/linear_solver.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>

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

namespace {

/// Direct solvers share one implementation (Eigen's wrappers have the same precompute/solve API).
template <typename Factorization, LinearSolverType Type> class DirectSolver final : public LinearSolver {
public:
  void analyze(const fem::SparseMatrix& A) override { m_factor.analyzePattern(A); }
  bool factorize(const fem::SparseMatrix& A) override {
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
};

/// Jacobi-preconditioned CG on the full symmetric matrix.
class CgSolver final : public LinearSolver {
public:
  void analyze(const fem::SparseMatrix& A) override { m_cg.analyzePattern(A); }
  bool factorize(const fem::SparseMatrix& A) override {
    m_cg.factorize(A);
    return m_cg.info() == Eigen::Success;
  }
  bool solve(const VecX& b, VecX& x, double relative_tolerance) override {
    m_cg.setTolerance(relative_tolerance);
    m_cg.setMaxIterations(std::max<Eigen::Index>(1000, b.size()));
    x = m_cg.solveWithGuess(b, x);
    m_iterations = static_cast<int>(m_cg.iterations());
    return m_cg.info() == Eigen::Success && x.allFinite();
  }
  int last_iterations() const override { return m_iterations; }
  LinearSolverType type() const override { return LinearSolverType::ConjugateGradient; }

private:
  Eigen::ConjugateGradient<fem::SparseMatrix, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double>>
      m_cg;
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
