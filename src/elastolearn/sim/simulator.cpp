#include <elastolearn/core/error.hpp>
#include <elastolearn/fem/mass.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::sim {

Simulator::Simulator(const Scene& scene)
    : m_scene(scene) {
  m_scene.validate();
  const auto& mesh = m_scene.mesh;
  m_dofs = fem::DofMap(mesh.num_vertices(), m_scene.prescribed_vertices());
  if (m_dofs.num_free() == 0)
    throw InputError("fixed", "every vertex is fixed or keyframed: nothing to simulate");
  m_system = fem::SystemMatrix(mesh.tets(), m_dofs);
  m_elastic = std::make_unique<fem::ElasticForce>(mesh, m_scene.material, m_scene.mass);
  m_dof_masses = fem::lumped_dof_masses(fem::lumped_vertex_masses(
      mesh.tets(), m_elastic->rest_data(), mesh.num_vertices(), m_scene.material.density));
  m_reduced_masses = m_dofs.restrict(m_dof_masses);
  if (m_scene.mass == fem::MassType::Consistent) {
    const auto blocks
        = fem::consistent_mass_blocks(m_elastic->rest_data(), m_scene.material.density);
    m_system.set_zero();
    m_system.add_element_blocks(blocks);
    m_consistent_values = m_system.values();
    fem::DofMap all(mesh.num_vertices(), {});
    fem::SystemMatrix full(mesh.tets(), all);
    full.add_element_blocks(blocks);
    m_consistent = full.matrix();
  }
  m_loads = std::make_unique<ExternalLoads>(m_dof_masses, m_scene.gravity, m_scene.loads);
  m_solver = make_linear_solver(m_scene.linear_solver);
  m_solver->analyze(m_system.matrix());
  m_x = flatten(mesh.rest_positions());
  m_v = VecX::Zero(m_x.size());
  if (m_scene.newton.absolute_tolerance == 0) {
    // Round-off floor of the force residual: forces are sums of terms of size K_ii·|x|, so a
    // relative target below ~1e-12 of that cannot be met once the motion has decayed.
    VecX f = VecX::Zero(m_x.size());
    m_system.set_zero();
    m_elastic->add_force_and_jacobian({ m_x, m_v, 0.0 }, 1.0, 0.0, f, m_system);
    double max_diagonal = 0;
    for (int i = 0; i < m_system.size(); ++i)
      max_diagonal = std::max(max_diagonal, m_system.matrix().coeff(i, i));
    m_scene.newton.absolute_tolerance = 1e-12 * max_diagonal * mesh.bounding_box_diagonal()
        * std::sqrt(double(m_dofs.num_free()));
  }
}

VecX Simulator::prescribed_positions(double t) const {
  VecX x = flatten(m_scene.mesh.rest_positions());
  for (const auto& k : m_scene.keyframes) {
    const Vec3 offset = k.offset_at(t);
    for (int v : k.vertices)
      x.segment<3>(3 * v) += offset;
  }
  if (const auto& tracked = m_scene.tracked)
    for (size_t j = 0; j < tracked->vertices.size(); ++j)
      x.segment<3>(3 * tracked->vertices[j]) = tracked->position_at(static_cast<int>(j), t);
  return x;
}

void Simulator::set_state(const VecX& x, const VecX& v, double time) {
  ELASTOLEARN_CHECK(x.size() == m_x.size() && v.size() == m_v.size(), "state size mismatch");
  m_x = x;
  m_v = v;
  forget_previous_step();
  m_time = time;
  m_start_time = time;
  m_step = 0;
}

double Simulator::kinetic_energy() const {
  if (m_scene.mass == fem::MassType::Consistent)
    return 0.5 * m_v.dot(m_consistent * m_v);
  return 0.5 * m_v.dot(m_dof_masses.cwiseProduct(m_v));
}

void Simulator::apply_mass(const VecX& dv, VecX& out) const {
  if (m_scene.mass == fem::MassType::Consistent)
    out.noalias() = m_consistent * dv;
  else
    out = m_dof_masses.cwiseProduct(dv);
}

void Simulator::sum_forces(const VecX& x, const VecX& v, double t, VecX& f) {
  f.setZero(x.size());
  const fem::ForceState state { x, v, t };
  m_elastic->add_force(state, f);
  m_loads->add_force(state, f);
  for (auto* term : m_extra_terms)
    term->add_force(state, f);
}

void Simulator::sum_jacobians(const VecX& x, const VecX& v, double t, double c_x, double c_v) {
  m_system.set_zero();
  const fem::ForceState state { x, v, t };
  m_elastic->add_jacobian(state, c_x, c_v, m_system);
  m_loads->add_jacobian(state, c_x, c_v, m_system);
  for (auto* term : m_extra_terms)
    term->add_jacobian(state, c_x, c_v, m_system);
}

NewtonReport Simulator::step() {
  // From the step count rather than m_time + h, so that round-off does not accumulate.
  const double t_next = m_start_time + (m_step + 1) * m_scene.dt;
  NewtonReport report = advance(t_next, m_scene.dt);
  if (!report.converged)
    report = advance_in_substeps(t_next, std::move(report));
  if (report.converged) {
    m_time = t_next;
    ++m_step;
  }
  return report;
}

NewtonReport Simulator::advance_in_substeps(double t_next, NewtonReport failed) {
  // Backward Euler's step matrix is M/h² + K (+ D/h): halving h quadruples the mass term, so a
  // step whose incremental problem Newton cannot solve (a material stiffening or softening
  // sharply within the step, elements near inversion) becomes better conditioned and, for h
  // small enough, convex. Each retry splits the whole step into twice as many equal substeps
  // from the same start; a step that converges whole is never split, so results that did not
  // need substeps are unchanged.
  const int halvings = m_scene.newton.max_step_halvings;
  if (halvings == 0)
    return failed;
  const VecX x_start = m_x, v_start = m_v; // allocated only on this (failure) path
  const double t_start = t_next - m_scene.dt;
  NewtonReport total = failed;
  for (int level = 1; level <= halvings; ++level) {
    const int substeps = 1 << level;
    const double h = m_scene.dt / substeps;
    m_x = x_start;
    m_v = v_start;
    forget_previous_step();
    bool converged = true;
    for (int i = 1; i <= substeps && converged; ++i) {
      const NewtonReport r = advance(i == substeps ? t_next : t_start + i * h, h);
      total.add_work(r);
      total.residual = r.residual;
      converged = r.converged;
      if (!converged)
        total.message = failed.message + "; in " + std::to_string(substeps) + " substeps, substep "
            + std::to_string(i) + ": " + r.message;
    }
    if (converged) {
      total.converged = true;
      total.substeps = substeps;
      total.message.clear();
      return total;
    }
  }
  m_x = x_start;
  m_v = v_start;
  forget_previous_step();
  return total;
}

NewtonReport Simulator::advance(double t_next, double h) {
  // Unknowns: free end-of-step velocities. Prescribed velocities follow the keyframes; they are
  // set once per step here (free entries are overwritten by each Newton iterate).
  m_v_new = (prescribed_positions(t_next) - m_x) / h;
  const auto& free = m_dofs.free_dofs();
  auto state_from = [&](const VecX& u) {
    for (size_t i = 0; i < free.size(); ++i)
      m_v_new[free[i]] = u[i];
    m_x_new = m_x + h * m_v_new;
  };
  auto inertia_minus_force = [&](VecX& g) {
    m_dv = m_v_new - m_v;
    apply_mass(m_dv, m_mass_dv);
    m_force = m_mass_dv / h - m_force;
    m_dofs.restrict_into(m_force, g);
  };
  NewtonProblem problem;
  problem.residual = [&](const VecX& u, VecX& g) {
    state_from(u);
    sum_forces(m_x_new, m_v_new, t_next, m_force);
    inertia_minus_force(g);
  };
  problem.jacobian = [&](const VecX& u, fem::SystemMatrix& A) {
    state_from(u); // same u as the preceding residual: the terms reuse their cached work
    sum_jacobians(m_x_new, m_v_new, t_next, h, 1.0);
    if (m_scene.mass == fem::MassType::Consistent)
      A.add_values(m_consistent_values, 1 / h);
    else
      A.add_diagonal(m_reduced_masses, 1 / h);
  };
  if (m_solver->type() == LinearSolverType::ConjugateGradient)
    problem.first_increment = &m_first_increment;
  VecX u;
  problem.start_is_prediction = first_iterate(h, u);
  NewtonReport report = newton(problem, u, *m_solver);
  if (!report.converged)
    return report;
  state_from(u);
  if (!m_x_new.allFinite()) {
    report.converged = false;
    report.message = "state is not finite";
    return report;
  }
  if (m_scene.newton.extrapolate_velocity) { // what first_iterate extrapolates from
    m_v_before = m_v;
    m_previous_step = h;
  }
  m_x = m_x_new;
  m_v = m_v_new;
  return report;
}

bool Simulator::first_iterate(double h, VecX& u) const {
  m_dofs.restrict_into(m_v, u);
  if (!m_scene.newton.extrapolate_velocity || m_previous_step != h)
    return false;
  const auto& free = m_dofs.free_dofs();
  for (size_t i = 0; i < free.size(); ++i)
    u[static_cast<Eigen::Index>(i)] += m_v[free[i]] - m_v_before[free[i]];
  return true;
}

NewtonReport Simulator::newton(const NewtonProblem& problem, VecX& u, LinearSolver& solver) {
  if (!m_scene.newton.retry_exact_tangent)
    return newton_solve(problem, u, m_system, solver, m_scene.newton);
  m_u_start = u;
  NewtonReport projected = newton_solve(problem, u, m_system, solver, m_scene.newton);
  if (projected.converged)
    return projected;
  // Newton's matrix projects every element's tangent to PSD, so it differs from the true
  // Jacobian wherever an element's tangent is indefinite (compression, a learned correction that
  // softens): Newton then converges only linearly and can stall above its target. Near a stable
  // solution the assembled exact Jacobian is positive definite even where element tangents are
  // not, and Newton with it converges quadratically. The retry therefore starts where the
  // projected solve stopped when that is closer to the solution than its start (a stall), and
  // from the start otherwise or if that fails; both retries keep the projected solve's target.
  NewtonOptions retry = m_scene.newton;
  retry.absolute_tolerance
      = std::max(retry.absolute_tolerance, retry.relative_tolerance * projected.initial_residual);
  m_elastic->set_project_tangent(false);
  NewtonReport exact;
  const bool progressed = projected.residual < projected.initial_residual && u.allFinite();
  if (progressed)
    exact = newton_solve(problem, u, m_system, solver, retry);
  if (!exact.converged) {
    u = m_u_start;
    NewtonReport from_start = newton_solve(problem, u, m_system, solver, retry);
    if (progressed) {
      from_start.add_work(exact);
      if (!from_start.converged)
        from_start.message
            = "from where it stopped: " + exact.message + "; from its start: " + from_start.message;
    }
    exact = std::move(from_start);
  }
  m_elastic->set_project_tangent(true);
  exact.add_work(projected);
  exact.initial_residual = projected.initial_residual;
  if (!exact.converged)
    exact.message = projected.message + "; with the exact tangent: " + exact.message;
  return exact;
}

VecX Simulator::total_force(const VecX& x, const VecX& v, double t) {
  VecX f;
  sum_forces(x, v, t, f);
  return f;
}

LinearSolver& Simulator::static_solver() {
  if (m_solver->type() != LinearSolverType::ConjugateGradient)
    return *m_solver;
  // Analysed once, on the first static solve: static cloud tracking solves one per frame.
  if (!m_static_solver) {
    m_static_solver = make_linear_solver(LinearSolverType::Cholmod);
    m_static_solver->analyze(m_system.matrix());
  }
  return *m_static_solver;
}

NewtonReport Simulator::solve_static(int load_steps) {
  ELASTOLEARN_CHECK(load_steps >= 1, "load_steps must be positive");
  const VecX x0 = m_x;
  const VecX zero = VecX::Zero(m_x.size());
  m_x_prescribed = prescribed_positions(m_time);
  auto state_from = [&](const VecX& u) {
    m_x_new = m_x_prescribed;
    const auto& free = m_dofs.free_dofs();
    for (size_t i = 0; i < free.size(); ++i)
      m_x_new[free[i]] = u[i];
  };
  NewtonProblem problem;
  problem.residual = [&](const VecX& u, VecX& g) {
    state_from(u);
    sum_forces(m_x_new, zero, m_time, m_force);
    g = -m_dofs.restrict(m_force);
  };
  problem.jacobian = [&](const VecX& u, fem::SystemMatrix&) {
    state_from(u);
    sum_jacobians(m_x_new, zero, m_time, 1.0, 0.0);
  };
  // The energy line search only without a correction: a learned one's continuation beyond its
  // trusted stretches is an exact energy only where every stretch is beyond the same end
  // (material/trusted_stretches.hpp), and Armijo steps on an energy whose gradient is not the
  // force stall (the learned test of a random benchmark case did, with its energy kernels).
  if (!m_scene.material.correction && m_extra_terms.empty())
    problem.energy = [&](const VecX& u) {
      state_from(u);
      m_force.setZero(m_x_new.size());
      m_loads->add_force({ m_x_new, zero, m_time }, m_force); // constant loads: potential −f·x
      return m_elastic->elastic_energy(m_x_new) - m_force.dot(m_x_new);
    };
  LinearSolver& solver = static_solver();
  VecX u = m_dofs.restrict(m_x);
  NewtonReport total;
  total.converged = true;
  for (int k = 1; k <= load_steps; ++k) {
    m_loads->set_scale(double(k) / load_steps);
    NewtonReport r = newton(problem, u, solver);
    total.add_work(r);
    total.residual = r.residual;
    if (k == 1)
      total.initial_residual = r.initial_residual;
    if (!r.converged) {
      total.converged = false;
      total.message = "static solve, load step " + std::to_string(k) + "/"
          + std::to_string(load_steps) + ": " + r.message;
      break;
    }
  }
  m_loads->set_scale(1.0);
  if (!total.converged) {
    m_x = x0;
    return total;
  }
  state_from(u);
  m_x = m_x_new;
  m_v.setZero();
  forget_previous_step();
  return total;
}

NewtonReport Simulator::apply_initial_condition() {
  const auto& ic = m_scene.initial;
  const double t0 = ic.kind == InitialCondition::Kind::Recorded ? ic.time : 0.0;
  m_x = prescribed_positions(t0); // rest, with prescribed vertices where they are at t0
  m_v.setZero();
  forget_previous_step();
  m_time = t0;
  m_start_time = t0;
  m_step = 0;
  NewtonReport report;
  report.converged = true;
  if (ic.kind == InitialCondition::Kind::Recorded) {
    // Free vertices take the recorded state; prescribed ones stay where their motion puts them.
    // Keyframed and tracked vertices keep their recorded velocities (with a consistent mass
    // matrix they enter the first step's inertia), fixed vertices do not move.
    const VecX x = flatten(ic.positions);
    for (int dof : m_dofs.free_dofs())
      m_x[dof] = x[dof];
    if (ic.velocities.rows() > 0)
      m_v = flatten(ic.velocities);
    for (int v : m_scene.fixed_vertices)
      m_v.segment<3>(3 * v).setZero();
  } else if (ic.kind == InitialCondition::Kind::Velocity) {
    const auto& X = m_scene.mesh.rest_positions();
    for (int v = 0; v < m_scene.mesh.num_vertices(); ++v)
      if (!m_dofs.is_prescribed_vertex(v))
        m_v.segment<3>(3 * v)
            = ic.velocity + ic.angular_velocity.cross(X.row(v).transpose() - ic.center);
  } else if (ic.kind == InitialCondition::Kind::StaticLoad) {
    // Equilibrium under gravity and the initial loads; the scene's own loads are not applied.
    auto scene_loads = std::move(m_loads);
    m_loads = std::make_unique<ExternalLoads>(m_dof_masses, m_scene.gravity, ic.static_loads);
    report = solve_static(ic.load_steps);
    m_loads = std::move(scene_loads);
  }
  return report;
}

} // namespace elastolearn::sim
