#pragma once
/// \file The radial-basis-function material correction of paper 000 (Eq. 1, §6.1 Eqs. 10 and 13):
/// an elastic RBF in the principal stretches plus a stretch-dependent correction Δα₁ of the
/// Rayleigh stiffness-damping coefficient. Rationale and conventions: docs/learning.md.
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/elastic_model.hpp>

#include <cmath>

namespace elastolearn::material {

/// RBF kernel φ(r) = √(r² + ε²) [-] of the stretch distance r = ‖σ − c‖. ε = 0 is the
/// polyharmonic kernel ‖σ − c‖ of paper Eq. (10); ε > 0 smooths its kink at r = 0 over a
/// stretch distance ε, so that N and its gradient are continuous everywhere.
inline double rbf_kernel(double squared_distance, double epsilon) {
  return std::sqrt(squared_distance + epsilon * epsilon);
}

/// N(σ, ḟ) = N_e(σ) + Δα₁(σ) · D ḟ with, for centres c_i (i = 1..m) and φ_i = φ(‖σ − c_i‖):
///   elastic    N_e(σ) = Σ_i w_i φ_i + A (σ − 1) + b                     [Pa]   (Eq. 10 + linear
///   term) damping    Δα₁(σ) = Σ_i v_i φ_i + aᵀ(σ − 1) + a₀                     [s]    (Eq. 13's
///   RBF)
/// where w_i ∈ R³ are the elastic weights, v_i the damping weights (the same centres), A, b and
/// a, a₀ optional linear polynomial tails (zero unless fitted), and D the 3×3 principal damping
/// tangent [Pa]: the Rayleigh stiffness-damping stress α₁ K ẋ of an element, restricted to the
/// principal stretch rates, is α₁ (∂P̂/∂σ) ḟ; D is the nominal model's ∂P̂/∂σ at rest
/// (rest_principal_tangent), which for the corotated nominal equals 2μI + λ11ᵀ at every stretch.
/// A positive Δα₁ adds damping. The rotational part of K ẋ stays with the nominal damping.
///
/// Permutation symmetry: the stretches are sorted descending (stable, stretch rates permuted
/// alongside) before evaluation and the outputs permuted back, so
/// N(Pσ, Pḟ) = P N(σ, ḟ) exactly for every permutation P; the fem layer already passes sorted
/// stretches, for which sorting is the identity.
/// `correction` and `correction_gradient` are exact, allocation-free and thread-safe.
/// At ε = 0 and σ exactly on a centre the kernel's gradient is taken as 0 (a subgradient).
class RbfCorrection final : public Correction {
  public:
  using Centres = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

  struct Parameters {
    Centres centres; ///< m × 3 centre stretches c_i [-] (m ≥ 0)
    Centres weights; ///< m × 3 elastic weights w_i [Pa]
    Mat3 linear = Mat3::Zero(); ///< A [Pa]
    Vec3 constant = Vec3::Zero(); ///< b [Pa]
    VecX damping_weights; ///< m damping weights v_i [s], or empty for no damping RBF
    Vec3 damping_linear = Vec3::Zero(); ///< a [s]
    double damping_constant = 0; ///< a₀ [s]
    Mat3 damping_tangent = Mat3::Zero(); ///< D [Pa]
    double epsilon = 1e-3; ///< kernel smoothing ε [-] (≥ 0)
  };

  /// Throws InputError("rbf_correction.<field>", ...) if sizes disagree (weights rows ≠ centres
  /// rows, damping weights neither empty nor m) or a value is not finite or ε < 0.
  explicit RbfCorrection(Parameters parameters);

  std::string name() const override { return "rbf"; }
  Vec3 correction(const Vec3& stretches, const Vec3& stretch_rates) const override;
  void correction_gradient(const Vec3& stretches, const Vec3& stretch_rates, Mat3& d_stretches,
      Mat3& d_stretch_rates) const override;
  std::unique_ptr<Correction> clone() const override;

  /// The elastic part N_e(σ) [Pa] alone (the correction at zero stretch rate).
  Vec3 elastic_correction(const Vec3& stretches) const;
  /// Δα₁(σ) [s], the correction of the Rayleigh stiffness coefficient.
  double damping_correction(const Vec3& stretches) const;

  int num_centres() const { return static_cast<int>(m_p.centres.rows()); }
  const Parameters& parameters() const { return m_p; }

  private:
  /// Evaluate at sorted stretches s and rates f; gradients if the pointers are non-null.
  Vec3 evaluate_sorted(const Vec3& s, const Vec3& f, Mat3* d_s, Mat3* d_f) const;
  Parameters m_p;
};

/// D for RbfCorrection::Parameters::damping_tangent: ∂P̂/∂σ of `model` at rest (σ = 1).
Mat3 rest_principal_tangent(const ElasticModel& model);

} // namespace elastolearn::material
