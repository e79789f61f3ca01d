#pragma once
/// \file The discrete equations of motion of a scene along a whole trajectory (paper 000 Eq. 2):
///   r_i = M (x_i − 2 x_{i−1} + x_{i−2}) / h² − f(x_i, v_i, t_i),   v_i = (x_i − x_{i−1}) / h,
/// for steps i = 1..T, with x_{−1} = x_0 − h v_0 (v_0 the initial velocity). This is exactly the
/// backward-Euler residual the Simulator drives to zero, so a simulated trajectory has r ≈ 0,
/// and the r of any other trajectory is the control force (Eq. 5) that would make it physical.
#include <elastolearn/fem/dof_map.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/fem/system_matrix.hpp>
#include <elastolearn/sim/boundary_conditions.hpp>
#include <elastolearn/sim/scene.hpp>

#include <memory>
#include <vector>

namespace elastolearn::learn {

class TrajectoryPhysics {
  public:
  /// Forces (elastic + correction + damping + gravity + loads) of `scene`'s material, with the
  /// scene's fixed and keyframed vertices prescribed. Lumped mass only (the paper's).
  /// Throws InputError for a consistent-mass scene.
  explicit TrajectoryPhysics(const sim::Scene& scene);

  const fem::DofMap& dofs() const { return m_dofs; }
  const VecX& dof_masses() const { return m_dof_masses; } ///< lumped, 3n [kg]
  double dt() const { return m_dt; }
  int num_frames() const { return m_frames; } ///< T (the trajectory has T + 1 states)
  const sim::Scene& scene() const { return m_scene; }

  /// r_i over all 3n dofs, prescribed entries zero [N]. `x_before` is x_{i−2} (x_0 − h v_0 for
  /// i = 1); t is the time of x_i. Caches the state for `jacobians`.
  void residual(const VecX& x_before, const VecX& x_previous, const VecX& x, double t, VecX& r);

  /// At the state of the last `residual` call, over the free dofs: K + D/h into `stiffness`
  /// and D into `damping`, where K ≈ −∂f/∂x and D ≈ −∂f/∂v are the (PSD-projected) Jacobians
  /// of the force. Then ∂r_i/∂x_i = M/h² + K + D/h, ∂r_i/∂x_{i−1} = −2M/h² − D/h and
  /// ∂r_i/∂x_{i−2} = M/h². The system matrices share one sparsity pattern built once.
  void jacobians(fem::SystemMatrix& stiffness, fem::SystemMatrix& damping);

  /// A system matrix with this problem's pattern, for `jacobians`.
  fem::SystemMatrix make_matrix() const { return fem::SystemMatrix(m_scene.mesh.tets(), m_dofs); }

  /// The elastic force, whose element cache is the state of the last `residual`
  /// (fem::ElasticForce::cached_frame: its principal frames there).
  const fem::ElasticForce& elastic_force() const { return *m_elastic; }
  /// Use the exact tangent instead of the PSD projection (derivative tests).
  void set_project_tangent(bool project) { m_elastic->set_project_tangent(project); }

  /// x_{−1} = x_0 − h v_0.
  VecX state_before_start(const VecX& x0, const VecX& v0) const { return x0 - m_dt * v0; }

  private:
  sim::Scene m_scene;
  fem::DofMap m_dofs;
  double m_dt = 0;
  int m_frames = 0;
  std::unique_ptr<fem::ElasticForce> m_elastic;
  std::unique_ptr<sim::ExternalLoads> m_loads;
  VecX m_dof_masses;
  VecX m_x, m_v; ///< state of the last residual
  double m_time = 0;
};

/// Velocities v_i = (x_i − x_{i−1})/h of a trajectory of T + 1 states (v_0 given).
std::vector<VecX> finite_difference_velocities(
    const std::vector<VecX>& positions, const VecX& v0, double dt);

} // namespace elastolearn::learn
