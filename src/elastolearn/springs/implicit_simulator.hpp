#pragma once
/// \file Corrected implicit learned simulator: backward Euler, linearised once per step
/// (Baraff & Witkin 1998), with the learned spring's force and slopes as the only spring model.
///
/// Per spring s = (i, j) with direction u, length L, learned force f(e, ė) on node i along u:
///   stiffness block K_s = a uu^T + b (I − uu^T),  a = max(−∂f/∂e, 0),  b = max(−f/L, 0)
///   damping block   D_s = d uu^T,                 d = max(−∂f/∂ė, 0)
/// (clamped so the system matrix stays SPD). The step solves, over the free nodes,
///   (M + h D + h² K) Δv = h (F(x, v) + F_ext + M g − h K v),  v⁺ = v + Δv,  x⁺ = x + h v⁺.
/// At a static equilibrium (v = 0, F + F_ext + M g = 0) the right side vanishes, so statics are
/// exact whatever the matrix; a rigid translation has K v = 0, so free fall is exact.
#include <elastolearn/springs/learned_simulator.hpp>

#include <Eigen/SparseCholesky>

namespace elastolearn::springs {

/// Statistics of the last implicit step.
struct ImplicitStepStats {
  bool direct = true; ///< solver used
  int cg_iterations = 0; ///< CG only
  double relative_residual = 0.0; ///< CG only: ‖b − A Δv‖/‖b‖
  bool converged = true; ///< CG reached its tolerance (direct: factorisation succeeded)
};

/// See the file comment. The sparsity pattern and the symbolic Cholesky analysis are computed
/// once at construction; each step refactorises numerically (direct) or runs warm-started
/// block-Jacobi PCG with a matrix-free product (cg). Parallel with oneTBB on large systems.
class ImplicitLearnedSimulator final : public SpringStepper {
  public:
  /// Throws InputError for invalid options, dt ≤ 0 or malformed loads.
  ImplicitLearnedSimulator(SpringSystem system, LearnedSpring spring, double dt,
      const LearnedSimulatorOptions& options, const Loads& loads = {});
  void step(SpringState& state) override;
  void set_loads(const Loads& loads) override;
  const SpringSystem& system() const override { return m_system; }
  double dt() const override { return m_dt; }
  bool is_local() const override { return false; }
  std::string_view name() const override { return "implicit"; }
  const ImplicitStepStats& last_step() const { return m_stats; }
  /// True if this simulator solves with the direct (Cholesky) solver.
  bool uses_direct_solver() const { return m_direct; }

  private:
  void compute_spring_terms(const SpringState& state);
  void build_rhs(const SpringState& state);
  void apply(const Positions& x, Positions& y) const; // y = A x on free nodes
  void solve_direct();
  void solve_cg();
  void setup_direct();

  SpringSystem m_system;
  LearnedSpring m_spring;
  double m_dt;
  LearnedSimulatorOptions m_options;
  bool m_direct = true;
  Positions m_external;
  Vec3 m_gravity = Vec3::Zero();
  ImplicitStepStats m_stats;

  // Per spring: direction u, force f (along u on node i), stiffness/damping scalars folded into
  // H_s = α uu^T + β (I − uu^T) with α = h d + h² a, β = h² b, and K_s's (a, b).
  Positions m_u;
  VecX m_force, m_alpha, m_beta, m_a, m_b;
  // Per node: block-Jacobi inverse of the diagonal block (CG), rhs, solution, CG work arrays.
  std::vector<Mat3> m_diag_inverse;
  Positions m_rhs, m_dv, m_r, m_z, m_p, m_q;

  // Direct solver: free-dof numbering, CSC matrix with a fixed pattern, value slots.
  std::vector<int> m_free_index; // node → free index or −1
  Eigen::SparseMatrix<double> m_matrix;
  std::vector<int> m_diag_slot; // per free node: 9 value indices (row-major 3×3)
  std::vector<int> m_offdiag_slot; // per spring with two free nodes: 9 indices of block (i, j) and
                                   // 9 of (j, i); −1 otherwise
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> m_ldlt;
  VecX m_flat_rhs, m_flat_solution;
};

} // namespace elastolearn::springs
