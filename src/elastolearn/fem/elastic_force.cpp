#include <elastolearn/core/error.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <Eigen/Eigenvalues>
#include <tbb/parallel_for.h>

namespace elastolearn::fem {

namespace {

/// Symmetric part of a 3×3 matrix with negative eigenvalues clamped to zero.
Mat3 symmetric_psd(const Mat3& a) {
  const Mat3 s = 0.5 * (a + a.transpose());
  Eigen::SelfAdjointEigenSolver<Mat3> eig(s);
  if (eig.eigenvalues().minCoeff() >= 0) return s;
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
         eig.eigenvectors().transpose();
}

} // namespace

ElasticForce::ElasticForce(const mesh::TetMesh& mesh, MaterialModel material)
    : m_tets(mesh.tets()), m_rest(precompute_rest_data(mesh)), m_material(std::move(material)) {
  ELASTOLEARN_CHECK(m_material.elastic != nullptr, "ElasticForce needs an elastic model");
  const int m = mesh.num_tets();
  const int n = mesh.num_vertices();
  m_force_buffer.assign(static_cast<size_t>(m) * 12, 0.0);
  m_vertex_offsets.assign(n + 1, 0);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a) ++m_vertex_offsets[m_tets(e, a) + 1];
  for (int v = 0; v < n; ++v) m_vertex_offsets[v + 1] += m_vertex_offsets[v];
  m_vertex_sources.resize(m_vertex_offsets[n]);
  std::vector<int> fill(m_vertex_offsets.begin(), m_vertex_offsets.end() - 1);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a) m_vertex_sources[fill[m_tets(e, a)]++] = 4 * e + a;
}

void ElasticForce::evaluate(const ForceState& state, bool want_jacobian, double c_x, double c_v) {
  const auto* elastic = m_material.elastic.get();
  const auto* correction = m_material.correction.get();
  const auto* damping = m_material.damping.get();
  const double density = m_material.density;
  const int m = static_cast<int>(m_tets.rows());
  if (want_jacobian && m_matrix_buffer.size() != static_cast<size_t>(m) * 144)
    m_matrix_buffer.assign(static_cast<size_t>(m) * 144, 0.0);

  tbb::parallel_for(tbb::blocked_range<int>(0, m, 256), [&](const tbb::blocked_range<int>& r) {
    for (int e = r.begin(); e < r.end(); ++e) {
      const TetRestData& rest = m_rest[e];
      const Eigen::Vector4i tet = m_tets.row(e).transpose();
      const auto xe = gather_tet(state.x, tet);
      const auto ve = gather_tet(state.v, tet);
      const auto frame = material::principal_frame(deformation_gradient(xe, rest));
      Vec3 rates = Vec3::Zero();
      if (correction) rates = material::stretch_rates(frame, deformation_gradient(ve, rest));
      const auto stress =
          material::corrected_principal_stress(*elastic, correction, frame.stretches, rates);
      const Mat3 P = material::first_piola(frame, stress.stress);
      Eigen::Map<Eigen::Matrix<double, 3, 4>> force(m_force_buffer.data() + 12 * e);
      force.noalias() = -rest.volume * P * rest.gradients;

      material::RayleighCoefficients alpha;
      if (damping) alpha = damping->coefficients(frame.stretches[0]);
      const bool need_stiffness = want_jacobian || alpha.alpha1 != 0;
      if (!need_stiffness && alpha.alpha0 == 0) continue;

      const double vertex_mass = density * rest.volume / 4.0;
      Eigen::Map<const Vec12> ve_flat(ve.data());
      Eigen::Map<Vec12> force_flat(force.data());
      force_flat -= alpha.alpha0 * vertex_mass * ve_flat;
      if (!need_stiffness) continue;

      const Mat9 H = material::first_piola_derivative(frame, stress.stress, stress.d_stretches,
                                                         m_project_tangent);
      const Mat12 K = element_matrix_from_tangent(H, rest);
      if (alpha.alpha1 != 0) force_flat.noalias() -= alpha.alpha1 * (K * ve_flat);
      if (!want_jacobian) continue;

      Eigen::Map<Mat12> J(m_matrix_buffer.data() + 144 * e);
      J = (c_x + c_v * alpha.alpha1) * K;
      J.diagonal().array() += c_v * alpha.alpha0 * vertex_mass;
      if (correction && c_v != 0) {
        const Mat3 d_rates =
            m_project_tangent ? symmetric_psd(stress.d_stretch_rates) : stress.d_stretch_rates;
        if (!d_rates.isZero(0))
          J += c_v * element_matrix_from_tangent(
                         material::first_piola_rate_derivative(frame, d_rates), rest);
      }
    }
  });
}

void ElasticForce::gather_forces(VecX& f) const {
  const int n = static_cast<int>(m_vertex_offsets.size()) - 1;
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 1024), [&](const tbb::blocked_range<int>& r) {
    for (int v = r.begin(); v < r.end(); ++v) {
      Vec3 sum = Vec3::Zero();
      for (int j = m_vertex_offsets[v]; j < m_vertex_offsets[v + 1]; ++j)
        sum += Eigen::Map<const Vec3>(m_force_buffer.data() + 3 * m_vertex_sources[j]);
      f.segment<3>(3 * v) += sum;
    }
  });
}

void ElasticForce::add_force(const ForceState& state, VecX& f) {
  evaluate(state, false, 0, 0);
  gather_forces(f);
}

void ElasticForce::add_force_and_jacobian(const ForceState& state, double c_x, double c_v, VecX& f,
                                          SystemMatrix& A) {
  evaluate(state, true, c_x, c_v);
  gather_forces(f);
  A.add_element_blocks(m_matrix_buffer);
}

double ElasticForce::elastic_energy(const VecX& x) const {
  double energy = 0;
  for (Eigen::Index e = 0; e < m_tets.rows(); ++e) {
    const auto frame = material::principal_frame(
        deformation_gradient(gather_tet(x, m_tets.row(e).transpose()), m_rest[e]));
    energy += m_rest[e].volume * m_material.elastic->energy(frame.stretches);
  }
  return energy;
}

VecX ElasticForce::max_stretches(const VecX& x) const {
  VecX out(m_tets.rows());
  for (Eigen::Index e = 0; e < m_tets.rows(); ++e)
    out[e] = material::principal_frame(
                 deformation_gradient(gather_tet(x, m_tets.row(e).transpose()), m_rest[e]))
                 .stretches[0];
  return out;
}

} // namespace elastolearn::fem
