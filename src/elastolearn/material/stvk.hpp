#pragma once
/// \file Saint Venant–Kirchhoff elasticity in principal stretches.
#include <elastolearn/material/elastic_model.hpp>

namespace elastolearn::material {

/// With Green strains Eᵢ = ½(σᵢ² − 1): Ψ = μ Σᵢ Eᵢ² + λ/2 (Σᵢ Eᵢ)²,
/// P̂ᵢ = σᵢ (μ(σᵢ² − 1) + ½λ Σⱼ(σⱼ² − 1)),
/// ∂P̂ᵢ/∂σⱼ = δᵢⱼ (μ(3σᵢ² − 1) + ½λ Σₖ(σₖ² − 1)) + λ σᵢ σⱼ.
/// Note StVK softens under strong compression (the energy is even in each σᵢ).
class StVKModel final : public ElasticModel {
  public:
  explicit StVKModel(const Lame& lame)
      : m_lame(lame) { }
  std::string name() const override { return "stvk"; }
  double energy(const Vec3& stretches) const override;
  Vec3 principal_stress(const Vec3& stretches) const override;
  Mat3 principal_stress_derivative(const Vec3& stretches) const override;
  std::unique_ptr<ElasticModel> clone() const override;
  const Lame& lame() const { return m_lame; }

  private:
  Lame m_lame;
};

} // namespace elastolearn::material
