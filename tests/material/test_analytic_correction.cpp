// The correction hook: N and its gradients, and the world-frame derivatives of P = U(P̂ + N)Vᵀ.
#include "model_zoo.hpp"

#include <elastolearn/core/error.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <support/finite_difference.hpp>
#include <support/material_states.hpp>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// Strong enough to matter next to μ ≈ 3.6e4 Pa: a = 2e5 Pa, b = 50 Pa·s, c = 3.
AnalyticCorrection test_correction() {
  return AnalyticCorrection({ 2e5, 50.0, 3.0 });
}

/// P(F, Ḟ) = U (P̂ + N(σ, diag(Uᵀ Ḟ V))) Vᵀ, evaluated the way the FEM layer will.
Mat3 corrected_piola(
    const ElasticModel& model, const Correction& n, const Mat3& F, const Mat3& F_rate) {
  const PrincipalFrame frame = principal_frame(F);
  const CorrectedStress cs
      = corrected_principal_stress(model, &n, frame.stretches, stretch_rates(frame, F_rate));
  return first_piola(frame, cs.stress);
}

} // namespace

TEST(AnalyticCorrection, GradientMatchesFiniteDifference) {
  const AnalyticCorrection n = test_correction();
  for (const auto& x : { Vec3(1.3, 0.9, 0.75), Vec3(1.1, 0.8, -0.3), Vec3(1, 1, 1) }) {
    for (const auto& r : { Vec3(0.5, -1.0, 2.0), Vec3::Zero().eval() }) {
      Eigen::VectorXd in(6);
      in << x, r;
      Mat3 ds, dr;
      n.correction_gradient(x, r, ds, dr);
      Eigen::MatrixXd J(3, 6);
      J << ds, dr;
      FdFunction f = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
        return n.correction(y.head<3>(), y.tail<3>());
      };
      // N is a polynomial of degree 3 in σ: 4th-order FD is exact up to rounding (~1e-12).
      expect_jacobian_matches(J, f, in, 1e-9, 1e-4, 1e3);
    }
  }
}

TEST(AnalyticCorrection, IsPermutationSymmetricAndZeroAtRest) {
  const AnalyticCorrection n = test_correction();
  const Vec3 x(1.3, 0.9, 0.75), r(0.5, -1.0, 2.0);
  const Vec3 nx = n.correction(x, r);
  const Vec3 ny = n.correction(Vec3(x[2], x[0], x[1]), Vec3(r[2], r[0], r[1]));
  EXPECT_LE((ny - Vec3(nx[2], nx[0], nx[1])).norm(), 1e-12 * nx.norm());
  EXPECT_EQ(n.correction(Vec3(1, 1, 1), Vec3::Zero()), Vec3::Zero());
  EXPECT_GT(nx.norm(), 1e3); // the parameters are not negligible
}

TEST(AnalyticCorrection, RejectsNonFiniteParameters) {
  EXPECT_THROW(AnalyticCorrection({ std::nan(""), 0, 0 }), InputError);
}

TEST(CorrectedStress, WithoutCorrectionIsTheModel) {
  const auto model = NeoHookeanFactory::make();
  const Vec3 s(1.3, 0.9, 0.75);
  const CorrectedStress cs = corrected_principal_stress(*model, nullptr, s, Vec3(1, 2, 3));
  EXPECT_EQ(cs.stress, model->principal_stress(s));
  EXPECT_EQ(cs.d_stretches, model->principal_stress_derivative(s));
  EXPECT_EQ(cs.d_stretch_rates, Mat3::Zero());
}

TEST(CorrectedStress, TangentAtZeroRateMatchesFiniteDifference) {
  // At Ḟ = 0 the stretch rates vanish for every F, so dP/dF of the corrected stress is the
  // principal-stretch formula applied to (P̂ + N, ∂(P̂ + N)/∂σ): exact, though N is not a gradient.
  const AnalyticCorrection n = test_correction();
  for (const auto& make : { &CorotatedFactory::make, &NeoHookeanFactory::make }) {
    const auto model = make();
    for (const auto& state : material_states()) {
      SCOPED_TRACE(model->name() + " " + state.name);
      const PrincipalFrame frame = principal_frame(state.F);
      const CorrectedStress cs
          = corrected_principal_stress(*model, &n, frame.stretches, Vec3::Zero());
      const Mat9 D = first_piola_derivative(frame, cs.stress, cs.d_stretches, false);
      FdFunction P = [&](const Eigen::VectorXd& f) {
        return vec(corrected_piola(*model, n, unvec(f), Mat3::Zero()));
      };
      // As in the model battery: FD error ≈ 1e-11 relative; 1e-8.
      expect_jacobian_matches(D, P, vec(state.F), 1e-8, 1e-4, test_lame().mu);
    }
  }
}

TEST(CorrectedStress, RateDerivativeMatchesFiniteDifference) {
  const AnalyticCorrection n = test_correction();
  const auto model = CorotatedFactory::make();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2, 2);
  for (const auto& state : material_states()) {
    SCOPED_TRACE(state.name);
    Mat3 Fdot;
    for (int k = 0; k < 9; ++k)
      Fdot.data()[k] = u(rng);
    const PrincipalFrame frame = principal_frame(state.F);
    const CorrectedStress cs
        = corrected_principal_stress(*model, &n, frame.stretches, stretch_rates(frame, Fdot));
    const Mat9 D = first_piola_rate_derivative(frame, cs.d_stretch_rates);
    FdFunction P = [&](const Eigen::VectorXd& fdot) {
      return vec(corrected_piola(*model, n, state.F, unvec(fdot)));
    };
    // P is affine in Ḟ at fixed F: the FD is exact up to rounding of P (|P| ~ 1e5 Pa, h =
    // 1e-4).
    expect_jacobian_matches(D, P, vec(Fdot), 1e-8, 1e-4, 1.0);
  }
}
