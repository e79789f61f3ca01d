#pragma once
/// \file The elastic force of a tet mesh with the corrected stress of paper 000 Eq. (1) and
/// Rayleigh damping f_d = −(α₀ M + α₁ K(x)) v, evaluated at the end-of-step state (Eq. 2).
#include <elastolearn/fem/force_term.hpp>
#include <elastolearn/fem/mass.hpp>
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/damping_model.hpp>
#include <elastolearn/material/elastic_model.hpp>
#include <elastolearn/material/element_stress.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <memory>
#include <vector>

namespace elastolearn::fem {

/// Everything the element kernel needs to know about the material. Shared, immutable.
struct MaterialModel {
  std::shared_ptr<const material::ElasticModel> elastic; ///< required
  std::shared_ptr<const material::Correction> correction; ///< optional N(F̂, Ḟ̂)
  std::shared_ptr<const material::DampingModel> damping; ///< optional Rayleigh
  double density = 1000; ///< ρ [kg/m³]
  /// Optional per-element stiffness scale s_e > 0 of a heterogeneous material (one per tet of
  /// the mesh it is used with; scene "material.regions"): element e's nominal stress is s_e P̂,
  /// so its stiffness and the α₁ damping of it scale too; a correction N is not scaled. Null:
  /// homogeneous (s_e = 1).
  std::shared_ptr<const std::vector<double>> stiffness_scale = nullptr;
};

/// Elastic (+correction) and Rayleigh damping forces of all tets, with their Jacobians.
///
/// Per element: F = Σ x_a g_aᵀ, SVD F = U F̂ Vᵀ, and the element's stress from the one kernel
/// material::element_stress (which states the physics: docs/learning.md, "Damping part"):
///   P = U (s_e P̂ + N) Vᵀ + (dP_d/dF : Ḟ),   f_a = −vol P g_a − α₀ (M_e v_e)_a
/// with s_e the element's stiffness scale (1 for a homogeneous material), (α₀, α₁) the damping
/// model's, from the element's largest stretch, M_e the element's lumped or consistent mass (the
/// scene's) and dP_d/dF = α₁ K^d(s_e P̂ + N(σ, 0)) + Δα₁ K^d(s_e P̂), K^d the damping tangent the
/// damping model names (material::DampingTangent), evaluated at the end-of-step state, the
/// flip-free one at its dissipative part (so that the damping dissipates) and the exact one as it
/// is: the nominal α₁ damps the *corrected* stiffness, the learned Δα₁ =
/// Correction::stiffness_damping(F̂) (paper Eq. 13; α₁ + Δα₁ kept ≥ 0) the nominal one, so that
/// the damping force stays linear in the correction's unknowns (learn::correction_force and
/// learn::CorrectionForceJacobian apply the correction's part of the same kernel).
/// K_e = vol Bᵀ (dP/dF) B of the corrected stress (clamped PSD in the Jacobian); the correction's
/// rate dependence adds D_e = vol Bᵀ ∂P/∂Ḟ B (symmetrised, clamped PSD). The Jacobian drops
/// ∂K/∂x·v (Rayleigh) and the variation of Ḟ̂ through U, V (correction), and projects c_x K_e +
/// c_v vol Bᵀ (dP_d/dF) B as a whole: standard, and the residual is still exact.
/// Element loops run in parallel (oneTBB): forces into per-element buffers gathered without
/// locks, element matrices straight into the SystemMatrix (SystemMatrix::add_elements).
class ElasticForce final : public ForceTerm {
  public:
  /// `mass` is the mass matrix the α₀ term scales (the scene's; lumped by default). Checks that a
  /// stiffness scale has one positive finite entry per tet.
  ElasticForce(const mesh::TetMesh& mesh, MaterialModel material, MassType mass = MassType::Lumped);

  /// Forces; caches each element's SVD and stress (and tangent, when Rayleigh α₁ ≠ 0) for
  /// add_jacobian at the same state.
  void add_force(const ForceState& state, VecX& f) override;
  void add_jacobian(const ForceState& state, double c_x, double c_v, SystemMatrix& A) override;

  /// Total elastic energy Σ vol (s_e Ψ(F̂) + ΔΨ(F̂)) [J], ΔΨ the correction's energy where it has
  /// one (material::Correction::has_elastic_energy), else the nominal model's alone; its gradient
  /// is then minus the force at v = 0. The static solve line-searches on it only without a
  /// correction (Simulator::solve_static).
  double elastic_energy(const VecX& x) const;

  /// Use the exact tangent instead of the PSD projection (for derivative tests; Newton wants
  /// the projection, which is the default).
  void set_project_tangent(bool project) { m_project_tangent = project; }

  /// Whether the element cache is that of positions x (the last add_force was at x); then
  /// cached_frame gives each element's principal frame there without another SVD.
  bool caches_positions(const VecX& x) const {
    return m_cache.size() == static_cast<size_t>(m_tets.rows()) && m_cached_x.size() == x.size()
        && m_cached_x == x;
  }
  /// Element e's principal frame at the last add_force's positions (see caches_positions).
  const material::PrincipalFrame& cached_frame(int e) const { return m_cache[e].frame; }

  const MaterialModel& material() const { return m_material; }
  const std::vector<TetRestData>& rest_data() const { return m_rest; }
  const Tets& tets() const { return m_tets; }

  private:
  /// What the force pass leaves for the Jacobian pass, per element.
  struct ElementCache {
    material::PrincipalFrame frame;
    material::CorrectedStress stress; ///< material::ElementStress::corrected
    double alpha0 = 0; ///< the damping model's α₀ [1/s]
    /// The stiffness-damping tangent dP_d/dF = α₁ K^d + Δα₁ K^nom,d: material::damping_tangent
    /// of material::ElementStress::damped (valid if has_damping).
    material::PrincipalTangent damping;
    bool has_damping = false;
  };
  bool cache_matches(const ForceState& state) const;
  void gather_forces(VecX& f) const;

  Tets m_tets;
  std::vector<TetRestData> m_rest;
  MaterialModel m_material;
  MassType m_mass;
  material::DampingTangent m_damping_tangent; ///< the damping model's (flip-free without one)
  std::vector<ElementCache> m_cache; ///< m, from the last add_force
  VecX m_cached_x, m_cached_v; ///< the state m_cache belongs to
  std::vector<double> m_force_buffer; ///< m·12
  std::vector<int> m_vertex_offsets; ///< vertex → range in m_vertex_sources
  std::vector<int> m_vertex_sources; ///< element·4 + local vertex
  bool m_project_tangent = true;
};

} // namespace elastolearn::fem
