#pragma once
/// \file Compressible neo-Hookean elasticity in principal stretches, made inversion-safe.
#include <elastolearn/material/elastic_model.hpp>

namespace elastolearn::material {

/// Ψ = μ/2 (I₁ − 3) − μ L + λ/2 L²,  I₁ = Σᵢ σᵢ²,  L = Σᵢ ℓ(σᵢ) (= ln J for an uninverted element),
/// P̂ᵢ = μ σᵢ + (λ L − μ) ℓ′(σᵢ)   (= μ(σᵢ − 1/σᵢ) + λ ln J / σᵢ when σᵢ ≥ ε for all i),
/// ∂P̂ᵢ/∂σⱼ = δᵢⱼ (μ + (λ L − μ) ℓ″(σᵢ)) + λ ℓ′(σᵢ) ℓ′(σⱼ).
///
/// Inversion: ℓ(x) = ln x for x ≥ ε and, below the threshold ε, its second-order Taylor
/// extension ℓ(x) = ln ε + (x − ε)/ε − (x − ε)²/(2ε²) (in the spirit of Irving et al. 2004 and
/// Teran et al. 2005, applied per stretch). ℓ is C² and strictly increasing, so Ψ, P̂ and ∂P̂/∂σ
/// are finite, consistent (P̂ = ∂Ψ/∂σ exactly) and continuous for every σ, including σ3 ≤ 0
/// (J ≤ 0), and the element is pushed back towards the uninverted state.
class NeoHookeanModel final : public ElasticModel {
  public:
  /// Default threshold ε of the ln extension (a stretch below 0.1 is already extreme
  /// compression).
  static constexpr double default_inversion_threshold = 0.1;

  /// Throws InputError unless 0 < inversion_threshold < 1.
  explicit NeoHookeanModel(
      const Lame& lame, double inversion_threshold = default_inversion_threshold);
  std::string name() const override { return "neohookean"; }
  double energy(const Vec3& stretches) const override;
  Vec3 principal_stress(const Vec3& stretches) const override;
  Mat3 principal_stress_derivative(const Vec3& stretches) const override;
  std::unique_ptr<ElasticModel> clone() const override;
  const Lame& lame() const { return m_lame; }
  double inversion_threshold() const { return m_eps; }

  /// The extended logarithm ℓ(x) and its first two derivatives.
  void extended_log(double x, double& l, double& dl, double& ddl) const;

  private:
  Lame m_lame;
  double m_eps;
  double m_log_eps;
};

} // namespace elastolearn::material
