#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/correction_force.hpp>
#include <elastolearn/learn/element_force_operator.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors fail("stress_reconstruction");

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

/// Nominal Rayleigh α₁ of an element (0 without a damping model).
double nominal_alpha1(const ReconstructionMesh& mesh, const Vec3& stretches) {
  return mesh.nominal.damping ? mesh.nominal.damping->coefficients(stretches[0]).alpha1 : 0.0;
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
    fail("nominal", "fitting the damping correction needs the nominal elastic model");
}

void CorrectionForceJacobian::element_rows(int e, Eigen::Ref<MatX> rows,
    RbfDesign::OutputMatrix& outputs, RbfDesign::OutputGradient& gradients,
    Eigen::RowVectorXd& damping_row) const {
  const material::ElasticModel* elastic = m_mesh.nominal.elastic.get();
  const int u = m_design.num_unknowns(), u_elastic = m_design.elastic_unknowns();
  const ElementState& st = m_states[e];
  const Eigen::Matrix<double, 12, 3> G = element_force_operator(m_mesh.rest[e], st.frame);
  const double alpha1 = elastic != nullptr ? nominal_alpha1(m_mesh, st.frame.stretches) : 0.0;
  if (alpha1 != 0) {
    m_design.output_matrix(st.frame.stretches, outputs, gradients);
    const Eigen::Matrix<double, 12, 12> D = alpha1
        * element_stiffness_damping_operator(m_mesh.rest[e], st, nominal_damping_tangent(m_mesh));
    rows.leftCols(u_elastic).noalias() = (G + D.leftCols<3>()) * outputs;
    rows.leftCols(u_elastic).noalias() += D.rightCols<9>() * gradients;
  } else {
    m_design.output_matrix(st.frame.stretches, outputs);
    rows.leftCols(u_elastic).noalias() = G * outputs;
  }
  if (u > u_elastic) {
    m_design.damping_row(st.frame.stretches, damping_row);
    rows.rightCols(u - u_elastic).noalias() = element_stiffness_damping_force(m_mesh.rest[e], st,
                                                  *elastic, nominal_damping_tangent(m_mesh))
        * damping_row;
  }
}

const MatX& CorrectionForceJacobian::transposed(const VecX& x, const VecX& v) {
  const int m = m_mesh.num_tets();
  const int u = m_design.num_unknowns(), u_elastic = m_design.elastic_unknowns();
  compute_element_states(m_mesh, x, v, m_states);
  m_jt.setZero();
  for (int first = 0; first < m; first += k_jacobian_batch) {
    const int count = std::min(k_jacobian_batch, m - first);
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 32), [&](const tbb::blocked_range<int>& r) {
      // Per-task work space: a few small buffers per 32 elements, next to their O(u) products.
      RbfDesign::OutputMatrix outputs(3, u_elastic);
      RbfDesign::OutputGradient gradients(9, u_elastic);
      Eigen::RowVectorXd damping_row(u - u_elastic);
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
  return m_jt;
}

VecX correction_force(const ReconstructionMesh& mesh, const material::Correction& correction,
    const VecX& x, const VecX& v) {
  const int m = mesh.num_tets();
  std::vector<ElementState> states;
  compute_element_states(mesh, x, v, states);
  std::vector<Vec12> element_forces(m);
  const material::ElasticModel* elastic = mesh.nominal.elastic.get();
  const material::DampingTangent kind = nominal_damping_tangent(mesh);
  tbb::parallel_for(tbb::blocked_range<int>(0, m, 256), [&](const tbb::blocked_range<int>& r) {
    for (int e = r.begin(); e < r.end(); ++e) {
      const ElementState& s = states[e];
      if (elastic == nullptr) {
        element_forces[e].noalias() = element_force_operator(mesh.rest[e], s.frame)
            * correction.correction(s.frame.stretches, s.stretch_rates);
        continue;
      }
      const material::CorrectedStress total = material::corrected_principal_stress(
          *elastic, &correction, s.frame.stretches, s.stretch_rates);
      const Vec3 nominal_stress = elastic->principal_stress(s.frame.stretches);
      element_forces[e].noalias()
          = element_force_operator(mesh.rest[e], s.frame) * (total.stress - nominal_stress);
      // ElasticForce's damping with the correction minus without it: α₁ on the corrected minus
      // the nominal stiffness, and the learned Δα₁ on the nominal one (same clamp α₁ + Δα₁ ≥ 0).
      const double alpha1 = nominal_alpha1(mesh, s.frame.stretches);
      const double change
          = material::corrected_stiffness_damping(alpha1, &correction, s.frame.stretches) - alpha1;
      if (alpha1 == 0 && change == 0)
        continue;
      if (alpha1 != 0) {
        material::CorrectedStress scratch;
        const material::CorrectedStress& elastic_stress
            = material::elastic_part(*elastic, &correction, s.frame.stretches, total, scratch);
        element_forces[e] += alpha1
            * (element_stiffness_damping_force(mesh.rest[e], s,
                   material::damping_tangent(
                       s.frame, elastic_stress.stress, elastic_stress.d_stretches, kind))
                - element_stiffness_damping_force(
                    mesh.rest[e], s, material::damping_tangent(*elastic, s.frame, kind)));
      }
      if (change != 0)
        element_forces[e]
            += change * element_stiffness_damping_force(mesh.rest[e], s, *elastic, kind);
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
    fail("frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  detail::check_frames(mesh, &dofs, positions, &velocities, &target_forces);
  if (dofs.num_free() == 0)
    fail("dofs", "no free degree of freedom");
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
