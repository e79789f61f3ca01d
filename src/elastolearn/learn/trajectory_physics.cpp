#include <elastolearn/core/error.hpp>
#include <elastolearn/fem/mass.hpp>
#include <elastolearn/learn/trajectory_physics.hpp>

namespace elastolearn::learn {

TrajectoryPhysics::TrajectoryPhysics(const sim::Scene& scene)
    : m_scene(scene) {
  m_scene.validate();
  if (m_scene.mass != fem::MassType::Lumped)
    throw InputError("mass", "learning supports the lumped mass matrix only (the paper's)");
  const auto& mesh = m_scene.mesh;
  m_dofs = fem::DofMap(mesh.num_vertices(), m_scene.prescribed_vertices());
  m_dt = m_scene.dt;
  m_frames = m_scene.frames;
  m_elastic = std::make_unique<fem::ElasticForce>(mesh, m_scene.material);
  m_dof_masses = fem::lumped_dof_masses(fem::lumped_vertex_masses(
      mesh.tets(), m_elastic->rest_data(), mesh.num_vertices(), m_scene.material.density));
  m_loads = std::make_unique<sim::ExternalLoads>(m_dof_masses, m_scene.gravity, m_scene.loads);
}

void TrajectoryPhysics::residual(
    const VecX& x_before, const VecX& x_previous, const VecX& x, double t, VecX& r) {
  const double h = m_dt;
  m_x = x;
  m_v = (x - x_previous) / h;
  m_time = t;
  VecX& f = r; // accumulate the force in r, then turn it into the residual in place
  f.setZero(x.size());
  const fem::ForceState state { m_x, m_v, t };
  m_elastic->add_force(state, f);
  m_loads->add_force(state, f);
  r = m_dof_masses.cwiseProduct(x - 2 * x_previous + x_before) / (h * h) - f;
  for (int v = 0; v < m_scene.mesh.num_vertices(); ++v)
    if (m_dofs.is_prescribed_vertex(v))
      r.segment<3>(3 * v).setZero();
}

void TrajectoryPhysics::jacobians(fem::SystemMatrix& stiffness, fem::SystemMatrix& damping) {
  const fem::ForceState state { m_x, m_v, m_time };
  stiffness.set_zero();
  m_elastic->add_jacobian(state, 1.0, 1.0 / m_dt, stiffness);
  damping.set_zero();
  m_elastic->add_jacobian(state, 0.0, 1.0, damping);
}

std::vector<VecX> finite_difference_velocities(
    const std::vector<VecX>& positions, const VecX& v0, double dt) {
  std::vector<VecX> v(positions.size());
  if (positions.empty())
    return v;
  v[0] = v0;
  for (size_t i = 1; i < positions.size(); ++i)
    v[i] = (positions[i] - positions[i - 1]) / dt;
  return v;
}

} // namespace elastolearn::learn
