#pragma once
/// \file Backward (implicit) Euler time stepping of a scene, paper 000 Eq. (2):
///   M (v₊ − v)/h = f(x₊, v₊, t₊),  x₊ = x + h v₊,
/// forces at the end of the step, solved for v₊ by Newton with the PSD Jacobian
/// M/h + D + h K. Fixed and keyframed vertices are removed from the system; the sparsity
/// pattern and the solver's symbolic analysis are built once, in the constructor.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/dof_map.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/fem/system_matrix.hpp>
#include <elastolearn/sim/boundary_conditions.hpp>
#include <elastolearn/sim/linear_solver.hpp>
#include <elastolearn/sim/newton.hpp>
#include <elastolearn/sim/scene.hpp>

#include <memory>
#include <vector>

namespace elastolearn::sim {

class Simulator {
  public:
  /// Precompute everything for `scene` (validated here). Starts at rest at t = 0; call
  /// `apply_initial_condition()` to set the scene's initial state.
  explicit Simulator(const Scene& scene);

  /// Set the scene's initial condition (rest, velocity field, static equilibrium under a load, or
  /// a recorded state) and its time (0, or the recorded state's). Returns the static solve's
  /// report (converged = true for the other kinds).
  NewtonReport apply_initial_condition();

  /// Advance one time step. A step Newton cannot solve whole is retried as 2, 4, …
  /// 2^NewtonOptions::max_step_halvings equal substeps (NewtonReport::substeps says how many
  /// it took). On failure (no split converged, non-finite state) the state is left unchanged
  /// and the report says why.
  NewtonReport step();

  /// Static equilibrium f(x) = 0 under the current loads scaled by 1/load_steps … 1 (load
  /// stepping).
  NewtonReport solve_static(int load_steps = 1);

  const VecX& positions() const { return m_x; } ///< flat 3n [m]
  const VecX& velocities() const { return m_v; } ///< flat 3n [m/s]
  double time() const { return m_time; }
  /// Steps taken since the state was last set (initial condition or set_state()).
  int step_index() const { return m_step; }
  /// Set the state at `time`; the following steps end at time + dt, time + 2·dt, ...
  void set_state(const VecX& x, const VecX& v, double time);

  double kinetic_energy() const;
  double elastic_energy() const { return m_elastic->elastic_energy(m_x); }
  /// Prescribed positions of all dofs at time t (free entries hold the rest positions).
  VecX prescribed_positions(double t) const;

  const Scene& scene() const { return m_scene; }
  const fem::DofMap& dofs() const { return m_dofs; }
  const fem::SystemMatrix& system_matrix() const { return m_system; }
  fem::ElasticForce& elastic_force() { return *m_elastic; }
  const VecX& dof_masses() const { return m_dof_masses; }
  /// Add a force term (e.g. control forces, position pulls). Not owned; must outlive the simulator.
  void add_force_term(fem::ForceTerm* term) { m_extra_terms.push_back(term); }
  /// The sum of every term's force (elastic and damping, gravity, loads, added terms) at a state
  /// (full 3n) [N].
  VecX total_force(const VecX& x, const VecX& v, double t);

  private:
  /// One backward Euler step of length h ending at t_next from the current state; the state
  /// becomes its end on success (time and step count are the caller's).
  NewtonReport advance(double t_next, double h);
  /// step()'s retries after `failed`, the report of the whole step.
  NewtonReport advance_in_substeps(double t_next, NewtonReport failed);
  /// Newton's first iterate for a step of length h: the free velocities extrapolated at constant
  /// acceleration, v + (v − v_before), when the previous step ended at the current state and had
  /// the same length (NewtonOptions::extrapolate_velocity); the current velocities otherwise.
  /// Returns whether it extrapolated.
  bool first_iterate(double h, VecX& u) const;
  /// The state was set from outside a step: the next step has no previous one to extrapolate.
  void forget_previous_step() { m_previous_step = 0; }
  /// newton_solve on the scene's system with `solver`, retried with the exact (unprojected)
  /// tangent when it fails and NewtonOptions::retry_exact_tangent is set (from where it stopped,
  /// then its start).
  NewtonReport newton(const NewtonProblem& problem, VecX& u, LinearSolver& solver);
  /// The solver of static solves: the scene's, unless that is Jacobi-CG. Statics has no mass
  /// term: its matrix is the stiffness alone, conditioned as badly as the mesh and the material
  /// make it (eigenvalues over seven decades on a random benchmark case), where CG, chosen for
  /// dynamics whose M/h² dominates, need not converge; a CHOLMOD factorisation serves it then.
  LinearSolver& static_solver();
  void sum_forces(const VecX& x, const VecX& v, double t, VecX& f);
  void sum_jacobians(const VecX& x, const VecX& v, double t, double c_x, double c_v);
  void apply_mass(const VecX& dv, VecX& out) const; ///< out = M dv (full 3n)

  Scene m_scene;
  fem::DofMap m_dofs;
  fem::SystemMatrix m_system;
  std::unique_ptr<fem::ElasticForce> m_elastic;
  std::unique_ptr<ExternalLoads> m_loads;
  std::vector<fem::ForceTerm*> m_extra_terms;
  std::unique_ptr<LinearSolver> m_solver;
  std::unique_ptr<LinearSolver> m_static_solver; ///< static_solver()'s own, when m_solver is CG
  VecX m_dof_masses; ///< lumped, full 3n
  VecX m_reduced_masses; ///< lumped, free dofs
  fem::SparseMatrix m_consistent; ///< full 3n×3n consistent mass (empty when lumped)
  VecX m_consistent_values; ///< consistent mass values in the system pattern
  VecX m_x, m_v;
  double m_time = 0;
  double m_start_time = 0; ///< time of the state that step 0 started from
  int m_step = 0; ///< steps since m_start_time; step k ends at m_start_time + k·dt
  // Work vectors (no allocation per Newton iteration).
  VecX m_x_new, m_v_new, m_force, m_dv, m_mass_dv, m_x_prescribed;
  VecX m_u_start; ///< Newton's start, kept for the exact-tangent retry
  VecX m_first_increment; ///< previous step's first Newton increment (warm start for CG)
  VecX m_v_before; ///< velocities at the start of the previous step (first_iterate)
  double m_previous_step = 0; ///< its length [s]; 0: none ended at the current state
};

} // namespace elastolearn::sim
