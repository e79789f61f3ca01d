// The typed battery run over every elastic model (CONVENTIONS.md "Tests"): zero stress at rest,
// rotation invariance, P = ∂Ψ/∂F, exact tangent = ∂P/∂F, projected tangent symmetric PSD.
#include "model_zoo.hpp"

#include <elastolearn/material/principal_stress.hpp>

#include <support/finite_difference.hpp>
#include <support/material_states.hpp>

#include <Eigen/Eigenvalues>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// Scale of stresses and stiffnesses: μ (test_lame: μ ≈ 3.6e4 Pa).
double stress_scale() {
  return test_lame().mu;
}

template <typename Factory> class ElasticModelBattery : public ::testing::Test {
  protected:
  std::unique_ptr<ElasticModel> model = Factory::make();
};
TYPED_TEST_SUITE(ElasticModelBattery, AllModelFactories);

} // namespace

TYPED_TEST(ElasticModelBattery, ZeroStressAndEnergyAtRest) {
  const ElasticModel& m = *this->model;
  for (const Mat3& F : { Mat3::Identity().eval(), rotated_stretch(Vec3(1, 1, 1), 99) }) {
    // Exact zero up to rounding of the rotation (1e-15 per entry).
    EXPECT_LE(first_piola(m, F).cwiseAbs().maxCoeff(), 1e-10 * stress_scale());
    EXPECT_NEAR(energy(m, F), 0.0, 1e-10 * stress_scale());
  }
}

TYPED_TEST(ElasticModelBattery, StressIsRotationInvariantAndIsotropic) {
  const ElasticModel& m = *this->model;
  std::mt19937 rng(42);
  for (const auto& state : material_states()) {
    const Mat3 R = random_rotation(rng), Q = random_rotation(rng);
    const Mat3 P = first_piola(m, state.F);
    const double tol = 1e-11 * std::max(P.norm(), stress_scale()); // SVD rounding only
    EXPECT_LE((first_piola(m, R * state.F) - R * P).norm(), tol)
        << state.name; // frame indifference
    EXPECT_LE((first_piola(m, state.F * Q) - P * Q).norm(), tol) << state.name; // isotropy
    EXPECT_NEAR(energy(m, R * state.F * Q), energy(m, state.F), 1e-11 * stress_scale())
        << state.name;
  }
}

TYPED_TEST(ElasticModelBattery, StressIsEnergyGradient) {
  const ElasticModel& m = *this->model;
  for (const auto& state : material_states()) {
    SCOPED_TRACE(state.name);
    auto psi = [&](const Eigen::VectorXd& f) { return energy(m, unvec(f)); };
    // 4th-order FD with h = 1e-4: truncation ~h⁴ Ψ⁽⁵⁾ and rounding ~1e-16 Ψ / h ≈ 1e-12 of the
    // stress scale (measured ≤ 4e-11 over all models and states); 1e-8 relative.
    const Eigen::VectorXd P = vec(first_piola(m, state.F));
    const Eigen::VectorXd fd = fd_gradient(psi, vec(state.F));
    EXPECT_LE(
        (P - fd).cwiseAbs().maxCoeff(), 1e-8 * std::max(fd.cwiseAbs().maxCoeff(), stress_scale()));
  }
}

TYPED_TEST(ElasticModelBattery, ExactTangentIsStressDerivative) {
  const ElasticModel& m = *this->model;
  for (const auto& state : material_states()) {
    SCOPED_TRACE(state.name);
    const Mat9 D = first_piola_derivative(m, state.F, /*project_psd=*/false);
    FdFunction P = [&](const Eigen::VectorXd& f) { return vec(first_piola(m, unvec(f))); };
    // Same FD error budget as above, one derivative higher (measured ≤ 3e-11); the stable limit
    // at (near-)repeated stretches is O(gap²) ≤ 1e-10 accurate.
    expect_jacobian_matches(D, P, vec(state.F), 1e-8, 1e-4, stress_scale());
  }
}

TYPED_TEST(ElasticModelBattery, ExactTangentOfHyperelasticModelIsSymmetric) {
  const ElasticModel& m = *this->model;
  for (const auto& state : material_states()) {
    const Mat9 D = first_piola_derivative(m, state.F, false);
    // A Hessian of Ψ(F); rounding of the 9×9 rotation products only.
    EXPECT_LE((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-11 * D.cwiseAbs().maxCoeff())
        << state.name;
  }
}

TYPED_TEST(ElasticModelBattery, ProjectedTangentIsSymmetricPositiveSemiDefinite) {
  const ElasticModel& m = *this->model;
  for (const auto& state : material_states()) {
    const Mat9 D = first_piola_derivative(m, state.F, /*project_psd=*/true);
    const double scale = D.cwiseAbs().maxCoeff();
    EXPECT_LE((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-12 * scale) << state.name;
    const double min_eig = Eigen::SelfAdjointEigenSolver<Mat9>(D).eigenvalues().minCoeff();
    EXPECT_GE(min_eig, -1e-9 * scale) << state.name;
  }
}

TYPED_TEST(ElasticModelBattery, ProjectionKeepsAnAlreadyPositiveTangent) {
  const ElasticModel& m = *this->model;
  for (const auto& state : small_tension_states()) {
    const Mat9 exact = first_piola_derivative(m, state.F, false);
    const double scale = exact.cwiseAbs().maxCoeff();
    const double min_eig = Eigen::SelfAdjointEigenSolver<Mat9>(exact).eigenvalues().minCoeff();
    ASSERT_GE(min_eig, -1e-9 * scale) << state.name << ": expected a PSD exact tangent here";
    const Mat9 projected = first_piola_derivative(m, state.F, true);
    EXPECT_LE((projected - exact).cwiseAbs().maxCoeff(), 1e-10 * scale) << state.name;
  }
}

TYPED_TEST(ElasticModelBattery, ProjectionRemovesNegativeDirectionsUnderCompression) {
  // Uniform compression: the flip eigenvalues (P̂ᵢ + P̂ⱼ)/(σᵢ + σⱼ) are negative for every model,
  // so the exact tangent is indefinite and the projection must change it.
  const ElasticModel& m = *this->model;
  const Mat3 F = rotated_stretch(Vec3(0.8, 0.78, 0.76), 31);
  const Mat9 exact = first_piola_derivative(m, F, false);
  const double scale = exact.cwiseAbs().maxCoeff();
  EXPECT_LT(Eigen::SelfAdjointEigenSolver<Mat9>(exact).eigenvalues().minCoeff(), -1e-3 * scale);
  const Mat9 projected = first_piola_derivative(m, F, true);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat9>(projected).eigenvalues().minCoeff(), -1e-9 * scale);
}

TYPED_TEST(ElasticModelBattery, PrincipalStressDerivativeMatchesFiniteDifference) {
  const ElasticModel& m = *this->model;
  for (const Vec3& s :
      { Vec3(1.3, 0.9, 0.75), Vec3(2.3, 1.6, 0.5), Vec3(1.15, 0.8, -0.3), Vec3(1.1, 0.8, 1e-3) }) {
    FdFunction p
        = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd { return m.principal_stress(x); };
    expect_jacobian_matches(m.principal_stress_derivative(s), p, s, 1e-8, 1e-4, stress_scale());
  }
}

TYPED_TEST(ElasticModelBattery, InvertedElementIsPushedBack) {
  // Growing the negative stretch toward zero must release energy for a model meant to survive
  // inversion: ∂Ψ/∂σ₃ < 0 at σ₃ < 0. StVK is not such a model: its energy is even in each σᵢ,
  // so it has a second rest state at σ₃ = −1 (checked as the known exception).
  const ElasticModel& m = *this->model;
  for (double s3 : { -0.9, -0.5, -0.1, -1e-3 }) {
    const Vec3 s(1.1, 0.9, s3);
    if (m.name() == "stvk") {
      EXPECT_NEAR(m.principal_stress(s)[2], -m.principal_stress(Vec3(1.1, 0.9, -s3))[2],
          1e-12 * stress_scale());
    } else {
      EXPECT_LT(m.principal_stress(s)[2], 0.0) << "sigma3 = " << s3;
    }
  }
}

TYPED_TEST(ElasticModelBattery, CloneBehavesLikeTheOriginal) {
  const ElasticModel& m = *this->model;
  const auto copy = m.clone();
  EXPECT_EQ(copy->name(), m.name());
  const Vec3 s(1.3, 0.9, 0.75);
  EXPECT_EQ(copy->principal_stress(s), m.principal_stress(s));
  EXPECT_EQ(copy->energy(s), m.energy(s));
}
