#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/fem/mass.hpp>
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/learn/correction_force.hpp>
#include <elastolearn/learn/element_force_operator.hpp>
#include <elastolearn/material/element_stress.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors correction_force_error("stress_reconstruction");

/// Free index of each element's 12 local dofs (−1 for prescribed).
std::vector<std::array<int, 12>> element_free_rows(
    const ReconstructionMesh& mesh, const fem::DofMap& dofs) {
  std::vector<std::array<int, 12>> rows(mesh.num_tets());
  for (int e = 0; e < mesh.num_tets(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c)
        rows[e][3 * a + c] = dofs.free_index(3 * mesh.tets(e, a) + c);
  return rows;
}

/// Element e's material for the kernel (material::element_stress): the nominal one of `mesh`
/// with `correction` (may be null). Without a nominal elastic model the correction contributes
/// its N term only: no nominal stress and no damping.
material::ElementMaterial element_material(
    const ReconstructionMesh& mesh, const material::Correction* correction, int e) {
  const fem::MaterialModel& nominal = mesh.nominal;
  return { nominal.elastic.get(), correction,
    nominal.elastic != nullptr ? nominal.damping.get() : nullptr,
    nominal.stiffness_scale ? (*nominal.stiffness_scale)[e] : 1.0 };
}

/// The stiffness the nominal's damping scales (as fem::ElasticForce chooses it).
material::DampingTangent nominal_damping_tangent(const ReconstructionMesh& mesh) {
  return material::damping_tangent_of(mesh.nominal.damping.get());
}

constexpr int k_jacobian_batch = 512; ///< elements per batch of CorrectionForceJacobian

} // namespace

CorrectionForceJacobian::CorrectionForceJacobian(
    const ReconstructionMesh& mesh, const fem::DofMap& dofs, const RbfDesign& design)
    : m_mesh(mesh)
    , m_design(design)
    , m_free_rows(element_free_rows(mesh, dofs))
    , m_states(mesh.num_tets())
    , m_jt(design.num_unknowns(), dofs.num_free())
    , m_batch(
          12 * std::min(k_jacobian_batch, std::max(1, mesh.num_tets())), design.num_unknowns()) {
  if (design.damping_unknowns() > 0 && mesh.nominal.elastic == nullptr)
    correction_force_error(
        "nominal", "fitting the damping correction needs the nominal elastic model");
  if (design.mass_damping_unknown() >= 0) {
    const VecX masses = fem::lumped_dof_masses(
        fem::lumped_vertex_masses(mesh.tets, mesh.rest, mesh.num_vertices, mesh.nominal.density));
    m_free_dofs = dofs.free_dofs();
    m_free_masses.resize(static_cast<Eigen::Index>(m_free_dofs.size()));
    for (size_t i = 0; i < m_free_dofs.size(); ++i)
      m_free_masses[static_cast<Eigen::Index>(i)] = masses[m_free_dofs[i]];
  }
}

void CorrectionForceJacobian::element_rows(int e, Eigen::Ref<Rows> rows,
    RbfDesign::OutputMatrix& outputs, RbfDesign::OutputGradient& gradients,
    Eigen::RowVectorXd& damping_row) const {
  const int u_elastic = m_design.elastic_unknowns();
  const ElementState& st = m_states[e];
  const fem::TetRestData& rest = m_mesh.rest[e];
  // The kernel without a correction gives how a correction's N and Δα₁ enter the element's
  // damping (ElementStress::damped_by_correction = weight · [N; ∂N/∂σ] + Δα₁ · per-Δα₁ pair), and
  // both are linear in the unknowns: N = A x_e, Δα₁ = d x_d.
  const material::ElementStress nominal = material::element_stress(
      element_material(m_mesh, nullptr, e), st.frame.stretches, Vec3::Zero());
  const material::DampingTangent kind = nominal_damping_tangent(m_mesh);
  const Eigen::Matrix<double, 12, 3> G = element_force_operator(rest, st.frame);
  const double weight = nominal.correction_damping_weight();
  if (weight != 0) {
    m_design.output_matrix(st.frame.stretches, outputs, gradients);
    const Eigen::Matrix<double, 12, 12> D
        = weight * element_stiffness_damping_operator(rest, st, kind);
    rows.leftCols(u_elastic).noalias() = (G + D.leftCols<3>()) * outputs;
    rows.leftCols(u_elastic).noalias() += D.rightCols<9>() * gradients;
  } else {
    m_design.output_matrix(st.frame.stretches, outputs);
    rows.leftCols(u_elastic).noalias() = G * outputs;
  }
  if (m_design.mass_damping_unknown() >= 0)
    rows.col(m_design.mass_damping_unknown()).setZero(); // transposed adds −M v at once
  if (m_design.damping_unknowns() > 0) {
    m_design.damping_row(st.frame.stretches, damping_row);
    rows.middleCols(u_elastic, m_design.damping_unknowns()).noalias()
        = element_stiffness_damping_force(rest, st,
              material::damping_tangent(st.frame, nominal.damped_per_alpha1_change(), kind))
        * damping_row;
  }
}

const MatX& CorrectionForceJacobian::transposed(const VecX& x, const VecX& v) {
  compute_element_states(m_mesh, x, v, m_states);
  return assemble_transposed(v);
}

const MatX& CorrectionForceJacobian::transposed(
    const VecX& x, const VecX& v, const fem::ElasticForce& frames) {
  compute_element_states(m_mesh, x, v, frames, m_states);
  return assemble_transposed(v);
}

const MatX& CorrectionForceJacobian::assemble_transposed(const VecX& v) {
  const int m = m_mesh.num_tets();
  const int u_elastic = m_design.elastic_unknowns();
  m_jt.setZero();
  for (int first = 0; first < m; first += k_jacobian_batch) {
    const int count = std::min(k_jacobian_batch, m - first);
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 32), [&](const tbb::blocked_range<int>& r) {
      // Per-task work space: a few small buffers per 32 elements, next to their O(u) products.
      RbfDesign::OutputMatrix outputs(3, u_elastic);
      RbfDesign::OutputGradient gradients(9, u_elastic);
      Eigen::RowVectorXd damping_row(m_design.damping_unknowns());
      for (int i = r.begin(); i < r.end(); ++i)
        element_rows(first + i, m_batch.middleRows(12 * i, 12), outputs, gradients, damping_row);
    });
    for (int i = 0; i < count; ++i)
      for (int l = 0; l < 12; ++l) {
        const int row = m_free_rows[first + i][l];
        if (row >= 0)
          m_jt.col(row) += m_batch.row(12 * i + l).transpose();
      }
  }
  if (const int k = m_design.mass_damping_unknown(); k >= 0) { // Δα₀'s force −M v (lumped)
    for (Eigen::Index i = 0; i < m_free_masses.size(); ++i)
      m_jt(k, i) = -m_free_masses[i] * v[m_free_dofs[i]];
  }
  return m_jt;
}

VecX correction_force(const ReconstructionMesh& mesh, const material::Correction& correction,
    const VecX& x, const VecX& v) {
  const int m = mesh.num_tets();
  std::vector<ElementState> states;
  compute_element_states(mesh, x, v, states);
  std::vector<Vec12> element_forces(m);
  const material::DampingTangent kind = nominal_damping_tangent(mesh);
  tbb::parallel_for(tbb::blocked_range<int>(0, m, 256), [&](const tbb::blocked_range<int>& r) {
    for (int e = r.begin(); e < r.end(); ++e) {
      const ElementState& s = states[e];
      // fem::ElasticForce's element stress with the correction minus without it: the kernel's
      // correction part, N and the damping it adds (one kernel evaluation, the nominal once).
      const material::ElementStress stress = material::element_stress(
          element_material(mesh, &correction, e), s.frame.stretches, s.stretch_rates);
      material::PrincipalTangent damping;
      const bool damped = stress.has_damping();
      if (damped)
        damping = material::damping_tangent(s.frame, stress.damped_by_correction(), kind);
      const Mat3 P = material::element_first_piola(
          s.frame, stress.correction, damped ? &damping : nullptr, s.deformation_rate);
      auto force = Eigen::Map<Eigen::Matrix<double, 3, 4>>(element_forces[e].data());
      force.noalias() = -mesh.rest[e].volume * P * mesh.rest[e].gradients;
      // Δα₀ as applied (kept α₀ + Δα₀ ≥ 0) on the lumped mass, as fem::ElasticForce damps it.
      const double alpha0_change = stress.mass_damping - stress.alpha.alpha0;
      if (alpha0_change != 0)
        force -= alpha0_change * (mesh.nominal.density * mesh.rest[e].volume / 4.0)
            * fem::gather_tet(v, mesh.tets.row(e).transpose());
    }
  });
  VecX f = VecX::Zero(3 * Eigen::Index(mesh.num_vertices));
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a)
      f.segment<3>(3 * mesh.tets(e, a)) += element_forces[e].segment<3>(3 * a);
  return f;
}

ForceMisfit correction_force_misfit(const ReconstructionMesh& mesh, const fem::DofMap& dofs,
    const material::Correction& correction, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces, int frame_stride) {
  if (frame_stride < 1)
    correction_force_error("frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  detail::check_frames(mesh, &dofs, positions, &velocities, &target_forces);
  if (dofs.num_free() == 0)
    correction_force_error("dofs", "no free degree of freedom");
  const std::vector<int> frames = detail::selected_frames(int(positions.size()), frame_stride);
  double residual = 0, target = 0;
  VecX g, f;
  for (int t : frames) {
    dofs.restrict_into(target_forces[t], g);
    dofs.restrict_into(correction_force(mesh, correction, positions[t], velocities[t]), f);
    residual += (f - g).squaredNorm();
    target += g.squaredNorm();
  }
  const double count = double(frames.size()) * (dofs.num_free() / 3.0);
  return { std::sqrt(residual / count), std::sqrt(target / count), int(frames.size()) };
}

} // namespace elastolearn::learn
