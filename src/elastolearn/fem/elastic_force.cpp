#include <elastolearn/core/error.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/material/element_stress.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace elastolearn::fem {

namespace {

/// a·A + b·B of two eigen-form tangents (the eigen-form is linear in dP/dF).
material::PrincipalTangent weighted_sum(
    double a, const material::PrincipalTangent& A, double b, const material::PrincipalTangent& B) {
  return { a * A.block + b * B.block, a * A.twist + b * B.twist, a * A.flip + b * B.flip };
}

/// The tangent without its non-dissipative part: the stretch block's symmetric part (the only one
/// that does work against a strain rate) and the twist and flip eigenvalues clamped at zero, the
/// block's antisymmetric part kept. Unchanged wherever the tangent already dissipates.
material::PrincipalTangent dissipative(const material::PrincipalTangent& t) {
  const Mat3 symmetric = 0.5 * (t.block + t.block.transpose());
  return { t.block - symmetric + material::symmetric_psd(symmetric), t.twist.cwiseMax(0.0),
    t.flip.cwiseMax(0.0) };
}

} // namespace

ElasticForce::ElasticForce(const mesh::TetMesh& mesh, MaterialModel material, MassType mass)
    : m_tets(mesh.tets())
    , m_rest(precompute_rest_data(mesh))
    , m_material(std::move(material))
    , m_mass(mass)
    , m_damping_tangent(material::damping_tangent_of(m_material.damping.get())) {
  ELASTOLEARN_CHECK(m_material.elastic != nullptr, "ElasticForce needs an elastic model");
  const int m = mesh.num_tets();
  if (const auto& scale = m_material.stiffness_scale) {
    ELASTOLEARN_CHECK(scale->size() == static_cast<size_t>(m),
        "stiffness scale has " + std::to_string(scale->size()) + " entries for " + std::to_string(m)
            + " tets");
    for (const double s : *scale)
      ELASTOLEARN_CHECK(std::isfinite(s) && s > 0, "stiffness scales must be positive and finite");
  }
  const int n = mesh.num_vertices();
  m_force_buffer.assign(static_cast<size_t>(m) * 12, 0.0);
  m_vertex_offsets.assign(n + 1, 0);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a)
      ++m_vertex_offsets[m_tets(e, a) + 1];
  for (int v = 0; v < n; ++v)
    m_vertex_offsets[v + 1] += m_vertex_offsets[v];
  m_vertex_sources.resize(m_vertex_offsets[n]);
  std::vector<int> fill(m_vertex_offsets.begin(), m_vertex_offsets.end() - 1);
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a)
      m_vertex_sources[fill[m_tets(e, a)]++] = 4 * e + a;
}

void ElasticForce::add_force(const ForceState& state, VecX& f) {
  const auto* elastic = m_material.elastic.get();
  const auto* correction = m_material.correction.get();
  const auto* damping = m_material.damping.get();
  const double density = m_material.density;
  const double* scales = m_material.stiffness_scale ? m_material.stiffness_scale->data() : nullptr;
  const int m = static_cast<int>(m_tets.rows());
  if (m_cache.size() != static_cast<size_t>(m))
    m_cache.resize(m);

  const material::ElementMaterial homogeneous { elastic, correction, damping, 1.0 };
  const bool need_rate = correction != nullptr || damping != nullptr;
  const bool need_rates = correction != nullptr && correction->depends_on_rates();

  tbb::parallel_for(tbb::blocked_range<int>(0, m, 256), [&](const tbb::blocked_range<int>& r) {
    material::ElementMaterial element = homogeneous;
    for (int e = r.begin(); e < r.end(); ++e) {
      const TetRestData& rest = m_rest[e];
      ElementCache& c = m_cache[e];
      if (scales)
        element.stiffness_scale = scales[e];
      const Eigen::Vector4i tet = m_tets.row(e).transpose();
      const auto xe = gather_tet(state.x, tet);
      const auto ve = gather_tet(state.v, tet);
      c.frame = material::principal_frame(deformation_gradient(xe, rest));
      Mat3 F_rate;
      if (need_rate)
        F_rate = deformation_gradient(ve, rest);
      const Vec3 rates = need_rates ? material::stretch_rates(c.frame, F_rate) : Vec3::Zero();
      // The element's stress and stiffness damping (material::element_stress states which
      // stiffness α₁ and Δα₁ damp). The flip-free damping tangent is applied at its dissipative
      // part: where a corrected tangent is indefinite, α₁ K v would feed energy in
      // (docs/materials.md, "Damping"); elsewhere nothing changes. The learning's correction
      // forces use it unprojected, linear in the correction; the exact tangent stays as it is,
      // to match other codes.
      const material::ElementStress stress
          = material::element_stress(element, c.frame.stretches, rates);
      c.stress = stress.corrected();
      c.alpha0 = stress.mass_damping;
      c.has_damping = stress.has_damping();
      if (c.has_damping) {
        c.damping = material::damping_tangent(c.frame, stress.damped(), m_damping_tangent);
        if (m_damping_tangent == material::DampingTangent::FlipFree)
          c.damping = dissipative(c.damping);
      }
      const Mat3 P = material::element_first_piola(
          c.frame, c.stress.stress, c.has_damping ? &c.damping : nullptr, F_rate);
      Eigen::Map<Eigen::Matrix<double, 3, 4>> force(m_force_buffer.data() + 12 * e);
      force.noalias() = -rest.volume * P * rest.gradients;
      if (c.alpha0 != 0) {
        if (m_mass == MassType::Lumped) {
          force -= c.alpha0 * (density * rest.volume / 4.0) * ve;
        } else {
          Eigen::Map<Vec12>(force.data()) -= c.alpha0
              * (consistent_mass_block(rest.volume, density) * Eigen::Map<const Vec12>(ve.data()));
        }
      }
    }
  });
  m_cached_x = state.x;
  m_cached_v = state.v;
  gather_forces(f);
}

bool ElasticForce::cache_matches(const ForceState& state) const {
  return caches_positions(state.x) && m_cached_v.size() == state.v.size() && m_cached_v == state.v;
}

void ElasticForce::add_jacobian(const ForceState& state, double c_x, double c_v, SystemMatrix& A) {
  if (!cache_matches(state)) {
    VecX scratch = VecX::Zero(state.x.size());
    add_force(state, scratch);
  }
  const auto* correction = m_material.correction.get();
  const double density = m_material.density;
  ELASTOLEARN_CHECK(A.num_elements() == m_tets.rows(), "SystemMatrix was built for another mesh");
  A.add_elements([&](int e, Mat12& J) {
    const TetRestData& rest = m_rest[e];
    const ElementCache& c = m_cache[e];
    // c_x K_e + c_v (α₁ K_e^damp + Δα₁ K_e^nom,damp) as one eigen-form tangent (the eigen-form is
    // linear in dP/dF), projected once as a whole.
    material::PrincipalTangent tangent;
    if (!c.has_damping) {
      tangent = material::principal_tangent(
          c.frame, c.stress.stress, c.stress.d_stretches, m_project_tangent);
    } else {
      tangent = weighted_sum(c_x,
          material::principal_tangent(c.frame, c.stress.stress, c.stress.d_stretches, false), c_v,
          c.damping);
      if (m_project_tangent)
        tangent = material::projected(tangent);
    }
    J = element_stiffness(c.frame, tangent, rest, c.has_damping ? 1.0 : c_x);
    if (c.alpha0 != 0) {
      if (m_mass == MassType::Lumped) {
        J.diagonal().array() += c_v * c.alpha0 * density * rest.volume / 4.0;
      } else {
        J += c_v * c.alpha0 * consistent_mass_block(rest.volume, density);
      }
    }
    if (correction && c_v != 0 && !c.stress.d_stretch_rates.isZero(0)) {
      // Project the damping tangent as a whole: the Rayleigh part α₁·block plus the correction's
      // rate part may be PSD together even where the rate part alone is not; projecting them
      // separately would overstate the damping and stall Newton.
      Mat3 rayleigh = Mat3::Zero();
      if (c.has_damping)
        rayleigh = c.damping.block;
      if (m_project_tangent)
        rayleigh = material::symmetric_psd(rayleigh);
      const Mat3 d_rates = m_project_tangent
          ? Mat3(material::symmetric_psd(rayleigh + c.stress.d_stretch_rates) - rayleigh)
          : c.stress.d_stretch_rates;
      if (!d_rates.isZero(0))
        J += c_v
            * element_matrix_from_tangent(
                material::first_piola_rate_derivative(c.frame, d_rates), rest);
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

double ElasticForce::elastic_energy(const VecX& x) const {
  const auto& scales = m_material.stiffness_scale;
  const material::Correction* correction
      = m_material.correction && m_material.correction->has_elastic_energy()
      ? m_material.correction.get()
      : nullptr;
  double energy = 0;
  for (Eigen::Index e = 0; e < m_tets.rows(); ++e) {
    const auto frame = material::principal_frame(
        deformation_gradient(gather_tet(x, m_tets.row(e).transpose()), m_rest[e]));
    double psi = (scales ? (*scales)[e] : 1.0) * m_material.elastic->energy(frame.stretches);
    if (correction)
      psi += correction->elastic_energy(frame.stretches);
    energy += m_rest[e].volume * psi;
  }
  return energy;
}

} // namespace elastolearn::fem
