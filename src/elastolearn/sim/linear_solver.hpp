#pragma once
/// \file Sparse symmetric positive-definite solvers behind one interface, with the symbolic
/// analysis done once per pattern and the numeric factorisation per Newton iteration.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/system_matrix.hpp>

#include <memory>
#include <string>

namespace elastolearn::sim {

/// Backends (name table shared by JSON and CLI):
/// - cholmod: CHOLMOD supernodal LLᵀ (robust default; fast with OpenBLAS),
/// - cg: Jacobi-preconditioned conjugate gradients (cheap for dynamics, M/h² dominates),
/// - eigen-ldlt: Eigen's SimplicialLDLT (reference fallback; slow above ~20k unknowns).
enum class LinearSolverType { Cholmod, ConjugateGradient, EigenLdlt };
std::string to_string(LinearSolverType type);
/// Throws InputError listing the valid names.
LinearSolverType linear_solver_type_from_string(const std::string& name);

class LinearSolver {
  public:
  virtual ~LinearSolver() = default;
  /// Symbolic analysis of A's pattern (fill-reducing ordering). Call once per pattern.
  virtual void analyze(const fem::SparseMatrix& A) = 0;
  /// Numeric factorisation (or preconditioner set-up). Returns false if A is not positive definite.
  virtual bool factorize(const fem::SparseMatrix& A) = 0;
  /// Solve A x = b. `relative_tolerance` applies to iterative solvers (‖Ax−b‖ ≤ tol‖b‖).
  /// Returns false on failure (breakdown, no convergence). `x` holds the initial guess on entry
  /// for iterative solvers.
  virtual bool solve(const VecX& b, VecX& x, double relative_tolerance) = 0;
  /// Solve A X = B for every column of B (direct solvers: one pass over the factor for all of
  /// them; iterative ones solve column by column from X = 0). Returns false on failure.
  virtual bool solve(const MatX& b, MatX& x, double relative_tolerance);
  /// Iterations used by the last solve (1 for direct solvers).
  virtual int last_iterations() const { return 1; }
  virtual LinearSolverType type() const = 0;
};

std::unique_ptr<LinearSolver> make_linear_solver(LinearSolverType type);

} // namespace elastolearn::sim
