#pragma once
/// \file Sparse reduced space-time optimisation (paper 000 §5.1, Eqs. 2–5).
///
/// Unknowns: reduced coordinates z_i of every state i = 0..T, x_i = o_i + Φ z_i, where o_i is an
/// origin trajectory (the constrained forward simulation: Φ then only has to correct it) and Φ
/// (3n × r, zero rows at prescribed dofs) the POD basis. Objective (Gauss–Newton on)
///   E(z) = ½ Σ_{i=1..T} ‖s Φᵀ r_i(x)‖²  +  ½ λ² Σ_{i=0..T} ‖S x_i − s_i‖²
/// with r_i the discrete equation of motion (TrajectoryPhysics, Eq. 2/3), S the observed dofs
/// seen in frame i (Observation::valid: a lost entry has no position term) and s_i their data
/// (Eq. 4), and s = τ²/m̄ (m̄ the mean vertex mass, τ = 1 % of the duration
/// T·h), which turns forces into the displacement they cause over τ, so that both terms are in
/// metres, λ is dimensionless and the balance does not depend on the time step. r_i couples x_i,
/// x_{i−1}, x_{i−2}, so JᵀJ is block-banded in time with block bandwidth 2: each Gauss–Newton step
/// is one banded block Cholesky solve, O(T r³). As in the paper, the Jacobian uses the force's
/// projected tangent (the correction's gradient is kept, since it is part of the simulator's
/// tangent too: it changes convergence, not the solution).
#include <elastolearn/core/progress.hpp>
#include <elastolearn/learn/banded_block_cholesky.hpp>
#include <elastolearn/learn/trajectory_physics.hpp>
#include <elastolearn/observe/observation.hpp>

#include <memory>
#include <vector>

namespace elastolearn::learn {

struct SpaceTimeOptions {
  double position_weight = 1.0; ///< λ of Eq. (4) [-] (see the file comment for the scaling)
  int max_iterations = 8; ///< Gauss–Newton iterations
  /// Stop when an iteration lowers E by less than this fraction of E.
  double tolerance = 1e-3;
  /// Throws InputError("space_time.<field>", ...) for an out-of-range field.
  void validate() const;
};

struct SpaceTimeResult {
  std::vector<VecX> positions; ///< optimised x_i, i = 0..T (3n each) [m]
  double initial_objective = 0; ///< E at the origin trajectory [m²]
  double objective = 0; ///< E at the result [m²]
  double physics_rms = 0; ///< √(mean over steps and free dofs of r_i²) of the result [N]
  double position_rms = 0; ///< √(mean over seen (frame, vertex) entries of ‖S x_i − s_i‖²) [m]
  int iterations = 0;
  double seconds = 0;
};

/// E and its Gauss–Newton normal equations for one scene, basis and data.
class SpaceTimeProblem {
  public:
  /// \param steps  T (the trajectory has T + 1 states); other parameters as optimize_space_time.
  SpaceTimeProblem(TrajectoryPhysics& physics, ConstRef<MatX> basis, int steps, const VecX& v0,
      const observe::Observation& observed, double position_weight);
  ~SpaceTimeProblem();
  SpaceTimeProblem(const SpaceTimeProblem&) = delete;
  SpaceTimeProblem& operator=(const SpaceTimeProblem&) = delete;

  struct Value {
    double physics = 0; ///< ½ Σ ‖s Φᵀ r_i‖² [m²]
    double position = 0; ///< ½ λ² Σ ‖S x_i − s_i‖² [m²]
    double residual_squares = 0; ///< Σ ‖r_i‖² over free dofs [N²]
    double position_squares = 0; ///< Σ ‖S x_i − s_i‖² [m²]
    double total() const { return physics + position; }
  };
  /// E at the trajectory x (T + 1 states of 3n).
  Value evaluate(const std::vector<VecX>& x);
  /// JᵀJ (block-banded, T + 1 blocks of r × r) and the gradient Jᵀ C of E with respect to z at x.
  void assemble(const std::vector<VecX>& x, BlockBandedMatrix& normal, VecX& gradient);
  int modes() const;
  int steps() const;

  private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// Minimise E from z = 0 (x = origin).
/// \param physics  the scene's forces with the current correction
/// \param basis    Φ, 3n × r
/// \param origin   o_i, T + 1 states (3n each), prescribed dofs as the scene prescribes them
/// \param v0       initial velocity (3n) [m/s]
/// \param observed the data s_i (T + 1 frames; observed vertices that are prescribed are ignored)
/// Throws InputError on inconsistent sizes.
SpaceTimeResult optimize_space_time(TrajectoryPhysics& physics, ConstRef<MatX> basis,
    const std::vector<VecX>& origin, const VecX& v0, const observe::Observation& observed,
    const SpaceTimeOptions& options, const ProgressCallback& progress = {});

/// The control forces of Eq. (5) along a trajectory: r_i for i = 1..T (entry 0 is zero), each
/// 3n with prescribed dofs zero [N]. With the nominal model's physics (no correction) this is
/// the total force the learned correction must produce (Eqs. 12–13's left side).
std::vector<VecX> trajectory_residuals(
    TrajectoryPhysics& physics, const std::vector<VecX>& positions, const VecX& v0);

} // namespace elastolearn::learn
