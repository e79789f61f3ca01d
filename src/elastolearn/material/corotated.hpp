#pragma once
/// \file Corotated linear elasticity in principal stretches (paper 000 §4.1).
#include <elastolearn/material/elastic_model.hpp>

namespace elastolearn::material {

/// Ψ = μ Σᵢ(σᵢ−1)² + λ/2 (Σᵢ(σᵢ−1))²,  P̂ = 2μ(F̂ − I) + λ tr(F̂ − I) I  (paper 000 §4.1),
/// ∂P̂/∂σ = 2μ I + λ 11ᵀ. Defined for inverted elements too (σ3 < 0).
class CorotatedModel final : public ElasticModel {
  public:
  explicit CorotatedModel(const Lame& lame)
      : m_lame(lame) { }
  std::string name() const override { return "corotated"; }
  double energy(const Vec3& stretches) const override;
  Vec3 principal_stress(const Vec3& stretches) const override;
  Mat3 principal_stress_derivative(const Vec3& stretches) const override;
  std::unique_ptr<ElasticModel> clone() const override;
  const Lame& lame() const { return m_lame; }

  private:
  Lame m_lame;
};

} // namespace elastolearn::material
