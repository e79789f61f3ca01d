// RbfCorrection (paper 000 Eqs. 1, 10, 13): exact gradients (finite differences), permutation
// symmetry, the split into elastic and damping parts, the smoothed kernel at a centre, and
// parameter validation.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <Eigen/Eigenvalues>

#include <support/bounded_hessian.hpp>
#include <support/finite_difference.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// m = 6 centres around rest, random weights of realistic size (elastic ~1e3 Pa, damping ~1e-2 s),
/// and linear tails.
RbfCorrection::Parameters test_parameters(double epsilon) {
  std::mt19937 rng(17);
  std::normal_distribution<double> g(0.0, 1.0);
  RbfCorrection::Parameters p;
  p.centres.resize(6, 3);
  p.centres << 1.0, 1.0, 1.0, 1.2, 1.0, 0.9, 1.1, 1.05, 0.8, 0.95, 0.9, 0.85, 1.3, 1.1, 1.0, 1.05,
      1.0, 0.7;
  p.weights.resize(6);
  for (auto& w : p.weights)
    w = 1e3 * g(rng);
  p.damping_weights.resize(6);
  for (auto& v : p.damping_weights)
    v = 1e-2 * g(rng);
  p.own_slope = 5e3;
  p.other_slope = -2e3;
  p.constant = 10;
  p.quadratic = Eigen::Vector4d(3e4, -2e4, 1e4, 4e4);
  p.neo_hookean = Eigen::Vector2d(-2e4, 3e4);
  p.damping_slopes = Vec3(0.01, -0.02, 0.005);
  p.damping_constant = 0.03;
  p.damping_quadratic = Vec3(2.0, -1.0, 0.5);
  p.epsilon = epsilon;
  return p;
}

/// Analytic [∂N/∂σ ∂N/∂ḟ] (3×6) vs 4th-order central differences of N over (σ, ḟ).
/// `floor`: the smallest Jacobian entry the tolerance is relative to (a continued correction can
/// have a zero tangent, whose finite differences are round-off).
void expect_gradient_matches_fd(
    const RbfCorrection& n, const Vec3& s, const Vec3& r, double tol, double floor = 1e-8) {
  Mat3 ds, dr;
  n.correction_gradient(s, r, ds, dr);
  Eigen::MatrixXd J(3, 6);
  J << ds, dr;
  Eigen::VectorXd in(6);
  in << s, r;
  const FdFunction f = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return n.correction(y.head<3>(), y.tail<3>());
  };
  expect_jacobian_matches(J, f, in, tol, 1e-5, floor);
}

} // namespace

TEST(RbfCorrection, GradientMatchesFiniteDifference) {
  // States at least 0.04 from every centre, so the kernel is smooth across the FD stencil
  // (4·1e-5): the O(h⁴) truncation error is ~ (h/r)⁴ ≈ 1e-13 relative; round-off in the FD
  // quotient of values ~1e4 Pa is ~1e-16·1e4/1e-5 ≈ 1e-7 Pa against gradients ~1e4–1e5: 1e-9.
  const RbfCorrection n(test_parameters(1e-3));
  const std::vector<Vec3> stretches { Vec3(1.15, 0.97, 0.88), Vec3(1.4, 1.2, 0.6),
    Vec3(0.9, 1.25, 1.02), Vec3(1.1, 0.95, -0.2) /* inverted */ };
  for (const Vec3& s : stretches) {
    for (const Vec3& r : { Vec3(0.3, -0.5, 0.1), Vec3::Zero().eval() }) {
      SCOPED_TRACE(
          testing::Message() << "stretches " << s.transpose() << " rates " << r.transpose());
      expect_gradient_matches_fd(n, s, r, 1e-7);
    }
  }
}

TEST(RbfCorrection, OnePassEvaluationEqualsTheSeparateCalls) {
  // correction_with_gradient (the element loops' call) shares the kernel evaluations of N and
  // ∂N: it must return exactly what correction and correction_gradient return.
  const RbfCorrection n(test_parameters(1e-3));
  for (const Vec3& s : { Vec3(1.15, 0.97, 0.88), Vec3(1.0, 1.0, 1.0), Vec3(1.1, 0.95, -0.2) }) {
    const Vec3 r(0.3, -0.5, 0.1);
    Mat3 ds, dr, ds1, dr1;
    n.correction_gradient(s, r, ds, dr);
    const Vec3 value = n.correction_with_gradient(s, r, ds1, dr1);
    EXPECT_EQ(value, n.correction(s, r));
    EXPECT_EQ(ds1, ds);
    EXPECT_EQ(dr1, dr);
  }
}

TEST(RbfCorrection, SmoothedKernelIsDifferentiableAtACentre) {
  // With ε = 0.05 the kernel √(r² + ε²) is smooth through a centre: FD agrees there too (curvature
  // scale ε ≫ FD step, truncation (h/ε)⁴ ≈ 2e-15).
  const RbfCorrection smooth(test_parameters(0.05));
  const Vec3 centre = smooth.parameters().centres.row(1).transpose(); // (1.2, 1.0, 0.9)
  expect_gradient_matches_fd(smooth, centre, Vec3(0.2, 0.1, -0.3), 1e-7);
  expect_gradient_matches_fd(smooth, centre + Vec3(1e-3, -2e-3, 0), Vec3(0.2, 0.1, -0.3), 1e-7);

  // ε = 0 (the paper's ‖σ − c‖): finite values and the documented subgradient 0 at the centre.
  const RbfCorrection kinked(test_parameters(0.0));
  Mat3 ds, dr;
  kinked.correction_gradient(centre, Vec3::Zero(), ds, dr);
  EXPECT_TRUE(ds.allFinite());
  EXPECT_TRUE(kinked.correction(centre, Vec3::Zero()).allFinite());
}

TEST(RbfCorrection, PermutationSymmetric) {
  const RbfCorrection n(test_parameters(1e-3));
  const Vec3 s(1.15, 0.97, 0.88), r(0.3, -0.5, 0.1);
  const Vec3 ns = n.correction(s, r);
  Mat3 ds, dr;
  n.correction_gradient(s, r, ds, dr);
  Eigen::Matrix3i perms;
  perms << 1, 0, 2, 2, 0, 1, 2, 1, 0;
  for (int k = 0; k < 3; ++k) {
    // Input i of the permuted call is input p[i] of the sorted one: N(Pσ, Pḟ) = P N(σ, ḟ), and
    // the gradients permute on both sides. The elastic part is bit-identical (each direction
    // sees the same view); D ḟ sums in another order, so allow round-off (1e-12 relative).
    Eigen::PermutationMatrix<3> P;
    P.indices() = perms.row(k).transpose();
    const Vec3 ps = P.transpose() * s, pr = P.transpose() * r;
    EXPECT_LE((n.correction(ps, pr) - P.transpose() * ns).norm(), 1e-12 * ns.norm());
    EXPECT_EQ(n.elastic_correction(ps), P.transpose() * n.elastic_correction(s));
    Mat3 pds, pdr;
    n.correction_gradient(ps, pr, pds, pdr);
    EXPECT_LE((pds - P.transpose() * ds * P).norm(), 1e-12 * ds.norm());
    EXPECT_LE((pdr - P.transpose() * dr * P).norm(), 1e-12 * dr.norm());
  }
}

TEST(RbfCorrection, EqualStretchesGiveEqualStresses) {
  // P = U diag(P̂ + N) Vᵀ is a function of F only if N_i = N_j whenever σ_i = σ_j (U, V are not
  // unique there). Exact equality: both directions evaluate the same view of the stretches.
  const RbfCorrection n(test_parameters(1e-3));
  for (const Vec3& s :
      { Vec3(1.1, 1.1, 0.9), Vec3(0.8, 1.2, 1.2), Vec3(1.05, 0.7, 1.05), Vec3::Ones().eval() }) {
    const Vec3 rates = Vec3(0.2, 0.2, 0.2);
    const Vec3 out = n.correction(s, rates);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (s[i] == s[j]) {
          EXPECT_EQ(out[i], out[j]) << "stretches " << s.transpose();
        }
      }
    }
  }
  // And the outputs approach each other continuously as two stretches meet.
  const Vec3 near(1.1 + 1e-7, 1.1, 0.9);
  const Vec3 out = n.correction(near, Vec3::Zero());
  EXPECT_LT(std::abs(out[0] - out[1]), 1e-7 * 1e5) << "Lipschitz with the slopes ~1e4–1e5 Pa";
}

TEST(RbfCorrection, ElasticAndDampingPartsAreTheDocumentedRbfs) {
  const RbfCorrection n(test_parameters(1e-3));
  const auto& p = n.parameters();
  const Vec3 s(1.15, 0.97, 0.88), r(0.3, -0.5, 0.1);
  // N(σ) and Δα₁(σ) are the documented RBF + linear tail; N does not see the stretch rates (the
  // damping acts through Δα₁ on the nominal stiffness, fem::ElasticForce).
  double expected_alpha = p.damping_slopes.dot(s - Vec3::Ones()) + p.damping_constant; // s sorted ↓
  for (int k = 0; k < 3; ++k)
    expected_alpha += p.damping_quadratic[k] * (s[k] - 1) * (s[k] - 1);
  Vec3 expected_elastic;
  for (int k = 0; k < 3; ++k) {
    const Vec3 y = stretch_view(s, k);
    expected_elastic[k] = p.own_slope * (y[0] - 1) + p.other_slope * (y[1] + y[2] - 2) + p.constant
        + p.quadratic[0] * (y[0] - 1) * (y[0] - 1) + p.quadratic[1] * (y[0] - 1) * (y[1] + y[2] - 2)
        + p.quadratic[2] * (y[1] + y[2] - 2) * (y[1] + y[2] - 2)
        + p.quadratic[3] * (y[1] - 1) * (y[2] - 1) + p.neo_hookean[0] * (y[0] + 1 / y[0] - 2)
        + p.neo_hookean[1] * (std::log(y[0] * y[1] * y[2]) / y[0] - (y[0] + y[1] + y[2] - 3));
    for (int i = 0; i < 6; ++i)
      expected_elastic[k]
          += p.weights[i] * rbf_kernel((y - p.centres.row(i).transpose()).squaredNorm(), p.epsilon);
  }
  for (int i = 0; i < 6; ++i) // s is sorted descending already
    expected_alpha += p.damping_weights[i]
        * rbf_kernel((s - p.centres.row(i).transpose()).squaredNorm(), p.epsilon);
  EXPECT_EQ(stretch_view(Vec3(1.0, 2.0, 3.0), 0), Vec3(1.0, 3.0, 2.0));
  EXPECT_NEAR(n.stiffness_damping(s), expected_alpha, 1e-14);
  // Δα₁ is a symmetric function of the stretches.
  EXPECT_NEAR(n.stiffness_damping(Vec3(s[2], s[0], s[1])), expected_alpha, 1e-14);
  EXPECT_LE((n.elastic_correction(s) - expected_elastic).norm(), 1e-10);
  EXPECT_EQ(n.correction(s, r), n.correction(s, Vec3::Zero()));
  Mat3 ds, dr;
  n.correction_gradient(s, r, ds, dr);
  EXPECT_TRUE(dr.isZero(0));
  EXPECT_TRUE(n.has_damping());
}

TEST(RbfCorrection, DampingFloorBoundsTheDampingCorrection) {
  RbfCorrection::Parameters p = test_parameters(1e-3);
  p.damping_weights.resize(0);
  p.damping_slopes = Vec3(1.0, 0.0, 0.0); // Δα₁ = max σ − 1 + a₀
  p.damping_constant = 0;
  p.damping_quadratic.setZero();
  p.damping_floor = -0.05;
  const RbfCorrection n(p);
  EXPECT_NEAR(
      n.stiffness_damping(Vec3(1.0, 1.1, 0.95)), 0.1, 1e-14); // the largest stretch, wherever it is
  EXPECT_EQ(n.stiffness_damping(Vec3(0.9, 0.8, 0.85)), -0.05); // −0.1 clamped
}

TEST(RbfCorrection, LinearTailIsAnIsotropicLameChange) {
  // a = 2Δμ + Δλ, b = Δλ reproduce 2Δμ(σ − 1) + Δλ tr(σ − 1) exactly: a wrong Young's modulus
  // of a corotated nominal is representable without kernels.
  RbfCorrection::Parameters p;
  const double dmu = -3e3, dlambda = 7e3;
  p.own_slope = 2 * dmu + dlambda;
  p.other_slope = dlambda;
  const RbfCorrection n(p);
  const Vec3 s(1.2, 0.9, 0.75);
  const Vec3 expected = 2 * dmu * (s - Vec3::Ones()) + dlambda * (s.sum() - 3) * Vec3::Ones();
  EXPECT_LE((n.correction(s, Vec3::Zero()) - expected).norm(), 1e-9);
}

TEST(RbfCorrection, ZeroWithoutWeightsAndWithoutDampingPart) {
  RbfCorrection::Parameters p = test_parameters(1e-3);
  p.weights.setZero();
  p.own_slope = p.other_slope = p.constant = 0;
  p.quadratic.setZero();
  p.neo_hookean.setZero();
  p.damping_weights.resize(0); // no damping RBF; the damping tail alone remains
  p.damping_slopes.setZero();
  p.damping_constant = 0;
  p.damping_quadratic.setZero();
  const RbfCorrection n(p);
  EXPECT_EQ(n.correction(Vec3(1.2, 1.0, 0.7), Vec3(1, 2, 3)), Vec3::Zero());
  EXPECT_EQ(n.stiffness_damping(Vec3(1.2, 1.0, 0.7)), 0.0);
  EXPECT_FALSE(n.has_damping());
  EXPECT_EQ(n.name(), "rbf");
  const auto copy = n.clone();
  EXPECT_EQ(copy->correction(Vec3(1.2, 1.0, 0.7), Vec3(1, 2, 3)), Vec3::Zero());
}

TEST(RbfCorrection, RejectsInconsistentParameters) {
  auto expect_error = [](const std::function<void(RbfCorrection::Parameters&)>& breaker,
                          const std::string& field) {
    RbfCorrection::Parameters p = test_parameters(1e-3);
    breaker(p);
    try {
      RbfCorrection n(p);
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), "rbf_correction." + field) << e.what();
    }
  };
  expect_error([](auto& p) { p.weights.conservativeResize(5); }, "weights");
  expect_error([](auto& p) { p.damping_weights.conservativeResize(4); }, "damping_weights");
  expect_error([](auto& p) { p.centres(2, 1) = std::nan(""); }, "centres");
  expect_error([](auto& p) { p.own_slope = std::nan(""); }, "own_slope");
  expect_error([](auto& p) { p.epsilon = -1; }, "epsilon");
  expect_error([](auto& p) { p.damping_constant = INFINITY; }, "damping_constant");
  expect_error([](auto& p) { p.quadratic[2] = std::nan(""); }, "quadratic");
  expect_error([](auto& p) { p.neo_hookean[1] = std::nan(""); }, "neo_hookean");
}

TEST(RbfCorrection, BlendIsTheWeightedSumOfTwoCorrections) {
  RbfCorrection::Parameters pa = test_parameters(1e-3), pb = test_parameters(1e-3);
  pb.centres.array() += 0.05;
  pb.weights *= -0.7;
  pb.damping_weights.resize(0); // b without a damping RBF
  pb.quadratic *= 2;
  pb.neo_hookean *= -1;
  const RbfCorrection a(pa), b(pb);
  const RbfCorrection half = blend(a, &b, 0.25), none = blend(a, nullptr, 0.5);
  EXPECT_EQ(half.num_centres(), 12);
  for (const Vec3& s : { Vec3(1.2, 1.0, 0.9), Vec3(0.95, 0.9, 0.8), Vec3(1.1, 1.1, 1.0) }) {
    EXPECT_LE((half.correction(s, Vec3::Zero())
                  - (0.75 * a.correction(s, Vec3::Zero()) + 0.25 * b.correction(s, Vec3::Zero())))
                  .norm(),
        1e-9 * a.correction(s, Vec3::Zero()).norm());
    EXPECT_NEAR(half.stiffness_damping(s),
        0.75 * a.stiffness_damping(s) + 0.25 * b.stiffness_damping(s), 1e-14);
    EXPECT_LE((none.correction(s, Vec3::Zero()) - 0.5 * a.correction(s, Vec3::Zero())).norm(),
        1e-9 * a.correction(s, Vec3::Zero()).norm());
  }
  pb.epsilon = 0.1;
  const RbfCorrection smoother(pb);
  EXPECT_THROW(blend(a, &smoother, 0.5), InputError);
}

TEST(RbfCorrection, RepeatedBlendsWithTheSameCorrectionKeepSharedCentresOnce) {
  // The loop's damped updates: C' = ½ (C + best), then ½ (C' + best) = ¼ C + ¾ best, ...
  RbfCorrection::Parameters pc = test_parameters(1e-3), pbest = test_parameters(1e-3);
  pbest.centres.array() += 0.03;
  pbest.weights *= 0.4;
  pbest.damping_weights *= -2;
  const RbfCorrection c(pc), best(pbest);
  const RbfCorrection quarter = blend(blend(c, &best, 0.5), &best, 0.5);
  EXPECT_EQ(quarter.num_centres(), c.num_centres() + best.num_centres());
  for (const Vec3& s : { Vec3(1.2, 1.0, 0.9), Vec3(0.95, 0.9, 0.8), Vec3(1.1, 1.1, 1.0) }) {
    const Vec3 want
        = 0.25 * c.correction(s, Vec3::Zero()) + 0.75 * best.correction(s, Vec3::Zero());
    EXPECT_LE((quarter.correction(s, Vec3::Zero()) - want).norm(), 1e-12 * want.norm());
    EXPECT_NEAR(quarter.stiffness_damping(s),
        0.25 * c.stiffness_damping(s) + 0.75 * best.stiffness_damping(s), 1e-14);
  }
}

namespace {

/// test_parameters with energy kernels: the quadratic tail moved into the energy subspace
/// (q₁ = 2 q₂), ε large enough that every stencil is smooth.
RbfCorrection energy_correction() {
  RbfCorrection::Parameters p = test_parameters(0.03);
  p.energy_kernels = true;
  p.quadratic[1] = 2 * p.quadratic[2];
  return RbfCorrection(std::move(p));
}

/// N = ∇ΔΨ at s by 4th-order central differences of elastic_energy (h = 1e-4: truncation
/// ~ (h/ε)⁴ ≈ 1e-10 relative; round-off 1e-16·|Ψ| / h with |Ψ| ~ 1e4 J/m³: 1e-8 Pa).
void expect_stress_is_energy_gradient(const RbfCorrection& n, const Vec3& s) {
  Eigen::MatrixXd stress(1, 3);
  stress.row(0) = n.elastic_correction(s).transpose();
  const FdFunction energy = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(1, n.elastic_energy(y.head<3>()));
  };
  expect_jacobian_matches(stress, energy, Eigen::VectorXd(s), 1e-7, 1e-4);
}

const std::vector<Vec3> k_energy_states { Vec3(1.15, 0.97, 0.88), Vec3(1.4, 1.2, 0.6),
  Vec3(0.9, 1.25, 1.02), Vec3(1.05, 1.05, 0.9) /* a tie */, Vec3(1.0, 1.0, 1.0) };

} // namespace

TEST(RbfCorrectionEnergy, StressIsTheGradientOfTheEnergy) {
  const RbfCorrection n = energy_correction();
  for (const Vec3& s : k_energy_states) {
    SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
    expect_stress_is_energy_gradient(n, s);
  }
}

TEST(RbfCorrectionEnergy, TangentIsSymmetricAndMatchesFiniteDifferences) {
  const RbfCorrection n = energy_correction();
  for (const Vec3& s : k_energy_states) {
    SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
    expect_gradient_matches_fd(n, s, Vec3::Zero(), 1e-7);
    Mat3 ds, dr;
    n.correction_gradient(s, Vec3::Zero(), ds, dr);
    EXPECT_LE((ds - ds.transpose()).norm(), 1e-10 * ds.norm()) << ds;
  }
}

TEST(RbfCorrectionEnergy, EqualStretchesGiveEqualStresses) {
  // Continuity of P = U diag(P̂ + N) Vᵀ at repeated stretches, where U, V are not unique.
  const RbfCorrection n = energy_correction();
  const Vec3 a = n.elastic_correction(Vec3(1.05, 1.05, 0.9));
  EXPECT_NEAR(a[0], a[1], 1e-9 * a.norm());
  const Vec3 rest = n.elastic_correction(Vec3::Ones());
  EXPECT_NEAR(rest[0], rest[2], 1e-9 * (rest.norm() + 1));
}

TEST(RbfCorrectionEnergy, WithoutSmoothingACopyOnTheStretchesAddsNothing) {
  // ε = 0 and σ a permutation of a centre: that copy's φ = 0 and its subgradient 0, as the scalar
  // kernel's. The kernels' part is N minus the same correction without kernel weights.
  RbfCorrection::Parameters p = test_parameters(0.0);
  p.energy_kernels = true;
  p.quadratic[1] = 2 * p.quadratic[2];
  RbfCorrection::Parameters tails_only = p;
  tails_only.weights.setZero();
  const RbfCorrection n(p), tails(std::move(tails_only));
  for (const Vec3& s : { Vec3(1.2, 1.0, 0.9), Vec3(1.0, 0.9, 1.2), Vec3(1.0, 1.0, 1.0) }) {
    SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
    Vec3 want = Vec3::Zero();
    Mat3 want_tangent = Mat3::Zero();
    for (Eigen::Index i = 0; i < p.centres.rows(); ++i) {
      Mat3 h;
      want += p.weights[i] * energy_kernel_gradient(s, p.centres.row(i).transpose(), 0.0, &h);
      want_tangent += p.weights[i] * h;
    }
    Mat3 ds, dr, tails_ds;
    const Vec3 got = n.correction_with_gradient(s, Vec3::Zero(), ds, dr)
        - tails.correction_with_gradient(s, Vec3::Zero(), tails_ds, dr);
    ASSERT_TRUE(got.allFinite() && ds.allFinite());
    EXPECT_LE((got - want).norm(), 1e-12 * want.norm());
    EXPECT_LE((ds - tails_ds - want_tangent).norm(), 1e-12 * want_tangent.norm());
  }
}

TEST(RbfCorrectionEnergy, StressKernelsAreNotAnEnergy) {
  // What the energy kernels fix: the stress kernels' tangent is not symmetric in general.
  const RbfCorrection n(test_parameters(0.03));
  Mat3 ds, dr;
  n.correction_gradient(Vec3(1.15, 0.97, 0.88), Vec3::Zero(), ds, dr);
  EXPECT_GT((ds - ds.transpose()).norm(), 1e-3 * ds.norm());
  EXPECT_THROW(n.elastic_energy(Vec3::Ones()), InputError);
}

TEST(RbfCorrectionEnergy, RefusesAQuadraticTailThatIsNotAGradient) {
  RbfCorrection::Parameters p = test_parameters(0.03);
  p.energy_kernels = true; // q = (3e4, −2e4, 1e4, 4e4): q₁ ≠ 2 q₂
  EXPECT_THROW(RbfCorrection(std::move(p)), InputError);
}

TEST(RbfCorrectionEnergy, ProjectedTangentOfTheCorrectedModelIsPositiveSemiDefinite) {
  // A correction that softens the model beyond stability (weights ~ the stiffness): the exact
  // tangent of P̂ + N has negative eigenvalues, and the projected one (Newton's) is PSD.
  RbfCorrection::Parameters p = test_parameters(0.03);
  p.energy_kernels = true;
  p.quadratic[1] = 2 * p.quadratic[2];
  p.weights *= 200;
  const RbfCorrection n(std::move(p));
  const CorotatedModel model(Lame::from_young_poisson(1e5, 0.4));
  bool some_negative = false;
  for (const Vec3& s : k_energy_states) {
    Mat3 F = Mat3::Zero();
    F.diagonal() = s;
    const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const PrincipalFrame frame = principal_frame(R * F);
    const CorrectedStress c = corrected_principal_stress(model, &n, frame.stretches, Vec3::Zero());
    const Mat9 exact = first_piola_derivative(frame, c.stress, c.d_stretches, false);
    const Mat9 projected = first_piola_derivative(frame, c.stress, c.d_stretches, true);
    EXPECT_LE((exact - exact.transpose()).norm(), 1e-8 * exact.norm()) << "an energy's Hessian";
    some_negative
        = some_negative || Eigen::SelfAdjointEigenSolver<Mat9>(exact).eigenvalues().minCoeff() < 0;
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat9>(projected).eigenvalues().minCoeff(),
        -1e-9 * projected.norm());
  }
  EXPECT_TRUE(some_negative) << "the test's correction must make the exact tangent indefinite";
}

namespace {

/// The corotated model the bounded continuation is learned on, E 1e5 Pa.
const CorotatedModel& bounded_nominal() {
  static const CorotatedModel model(Lame::from_young_poisson(1e5, 0.4));
  return model;
}

/// [0.9, 1.2], continued as `continuation` says (bounded by bounded_nominal()'s rest stiffness).
TrustedStretches trusted_interval(Continuation continuation) {
  TrustedStretches t { 0.9, 1.2, continuation };
  t.nominal_stiffness = bounded_nominal().principal_stress_derivative(Vec3::Ones());
  return t;
}

/// energy_correction() trusted in [0.9, 1.2] only, continued as `continuation` says.
RbfCorrection trusted_energy_correction(Continuation continuation = Continuation::edge_hessian) {
  RbfCorrection::Parameters p = energy_correction().parameters();
  p.trusted = trusted_interval(continuation);
  return RbfCorrection(std::move(p));
}

/// A correction that removes more than bounded_nominal()'s stiffness near the trusted interval's
/// lower edge (the weights of ProjectedTangentOfTheCorrectedModelIsPositiveSemiDefinite).
RbfCorrection softening_correction(Continuation continuation) {
  RbfCorrection::Parameters p = test_parameters(0.03);
  p.energy_kernels = true;
  p.quadratic[1] = 2 * p.quadratic[2];
  p.weights *= 200;
  p.trusted = trusted_interval(continuation);
  return RbfCorrection(std::move(p));
}

/// The smallest eigenvalue of K₀^(−½) A K₀^(−½) for K₀ bounded_nominal()'s rest stiffness: A's
/// stiffness relative to K₀ in its softest direction (generalized eigenvalues of (A, K₀)).
double relative_to_rest_stiffness(const Mat3& a) {
  const Mat3 k0 = bounded_nominal().principal_stress_derivative(Vec3::Ones());
  return Eigen::GeneralizedSelfAdjointEigenSolver<Mat3>(0.5 * (a + a.transpose()), k0)
      .eigenvalues()
      .minCoeff();
}

} // namespace

TEST(RbfCorrectionEnergy, BeyondItsTrustedStretchesItKeepsTheStiffnessOfTheEdge) {
  // Continuation::edge_hessian (files written before "continuation"): the edge's whole Hessian.
  const RbfCorrection unbounded = energy_correction();
  const RbfCorrection n = trusted_energy_correction();
  Mat3 h, unused;
  // Inside: the formula itself.
  const Vec3 inside(1.1, 1.0, 0.95);
  EXPECT_EQ(n.elastic_correction(inside), unbounded.elastic_correction(inside));
  // Outside: the second-order expansion at the nearest trusted point c.
  for (const Vec3& s : { Vec3(1.5, 1.0, 0.95), Vec3(1.4, 1.3, 0.6), Vec3(0.7, 1.1, 1.6) }) {
    SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
    const Vec3 c = s.cwiseMax(0.9).cwiseMin(1.2);
    unbounded.correction_gradient(c, Vec3::Zero(), h, unused);
    const Vec3 expected = unbounded.elastic_correction(c) + h * (s - c);
    EXPECT_LE((n.elastic_correction(s) - expected).norm(), 1e-12 * expected.norm());
    Mat3 ds;
    EXPECT_LE((n.correction_with_gradient(s, Vec3::Zero(), ds, unused) - expected).norm(),
        1e-12 * expected.norm());
    EXPECT_LE((ds - h).norm(), 1e-12 * h.norm()) << "the tangent is the edge's, symmetric";
    // Symmetric in the stretches like ΔΨ: permuting σ permutes N.
    const Vec3 swapped = n.elastic_correction(Vec3(s[2], s[0], s[1]));
    EXPECT_LE(
        (swapped - Vec3(expected[2], expected[0], expected[1])).norm(), 1e-12 * expected.norm());
  }
  // The stiffness stays that of the edge: N is linear along a clamped direction, while the
  // formula's (cubic and neo-Hookean tails) is not.
  const auto along
      = [](const RbfCorrection& c, double s1) { return c.elastic_correction(Vec3(s1, 1.0, 0.95)); };
  const Vec3 curvature = along(n, 1.6) - 2 * along(n, 1.45) + along(n, 1.3);
  EXPECT_LE(curvature.norm(), 1e-9 * along(n, 1.6).norm());
  const Vec3 formula_curvature
      = along(unbounded, 1.6) - 2 * along(unbounded, 1.45) + along(unbounded, 1.3);
  EXPECT_GT(formula_curvature.norm(), 1e-3 * along(unbounded, 1.6).norm());
  // C¹ across the edge: N changes by O(h) over [1.2 − h, 1.2 + h], as ∂N/∂σ says.
  const double step = 1e-6;
  unbounded.correction_gradient(Vec3(1.2, 1.0, 0.95), Vec3::Zero(), h, unused);
  const Vec3 jump = along(n, 1.2 + step) - along(n, 1.2 - step);
  EXPECT_LE((jump - 2 * step * h.col(0)).norm(), 1e-6 * (2 * step * h.col(0)).norm());
}

TEST(RbfCorrectionEnergy, OutsideItsTrustedStretchesItIsStillAnEnergy) {
  // Where every stretch is beyond the same edge, c is fixed and N = ∇ΔΨ exactly (the continued
  // energy is a quadratic there); its tangent matches finite differences of N. Both
  // continuations; the softening correction's edge Hessian is beyond the bound there.
  for (const Continuation continuation :
      { Continuation::edge_hessian, Continuation::bounded_softening })
    for (const RbfCorrection& n :
        { trusted_energy_correction(continuation), softening_correction(continuation) })
      for (const Vec3& s : { Vec3(1.5, 1.35, 1.25), Vec3(0.8, 0.7, 0.85) }) {
        SCOPED_TRACE(testing::Message() << "stretches " << s.transpose() << ", continuation "
                                        << static_cast<int>(continuation));
        expect_stress_is_energy_gradient(n, s);
        expect_gradient_matches_fd(n, s, Vec3::Zero(), 1e-7);
      }
}

TEST(RbfCorrectionEnergy, BeyondItsTrustedStretchesTheBoundedContinuationKeepsTheNominalStable) {
  // Continuation::bounded_softening (what learning writes): beyond the edge the tangent is the
  // edge's Hessian H bounded below so that K₀ + H ⪰ β K₀ (K₀ the nominal's rest stiffness), so
  // the corrected corotated model (whose stretch block is K₀ everywhere) keeps at least β of its
  // stiffness in every stretch direction however far the stretches go. The edge Hessian itself
  // (edge_hessian) makes it unstable there. Checked through the generalized eigenproblem of
  // (H, K₀), not the implementation's K₀^(½) route.
  const RbfCorrection hessian = softening_correction(Continuation::edge_hessian);
  const RbfCorrection bounded = softening_correction(Continuation::bounded_softening);
  const double beta = bounded.parameters().trusted.kept_stiffness;
  ASSERT_EQ(beta, kKeptStiffness);
  const auto corrected_block = [&](const RbfCorrection& n, const Vec3& s) {
    const CorrectedStress c = corrected_principal_stress(bounded_nominal(), &n, s, Vec3::Zero());
    return principal_tangent(
        { Mat3::Identity(), s, Mat3::Identity() }, c.stress, c.d_stretches, false)
        .block;
  };
  const Vec3 c(1.0, 0.95, 0.9); // the edge point of the states below
  Mat3 edge, unused;
  hessian.correction_gradient(c, Vec3::Zero(), edge, unused);
  const Mat3 k0 = bounded_nominal().principal_stress_derivative(Vec3::Ones());
  ASSERT_LT(relative_to_rest_stiffness(k0 + edge), 0) << "the test needs an unstable edge";
  const Mat3 expected_tangent = bounded_hessian(edge, k0, beta);
  for (const Vec3& s : { Vec3(1.0, 0.95, 0.8), Vec3(1.0, 0.95, 0.6), Vec3(1.0, 0.95, 0.4) }) {
    SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
    Mat3 ds;
    const Vec3 n = bounded.correction_with_gradient(s, Vec3::Zero(), ds, unused);
    EXPECT_LE((ds - expected_tangent).norm(), 1e-9 * edge.norm());
    EXPECT_LE(
        (n - (bounded.elastic_correction(c) + expected_tangent * (s - c))).norm(), 1e-9 * n.norm());
    EXPECT_NEAR(relative_to_rest_stiffness(corrected_block(bounded, s)), beta, 1e-9);
    EXPECT_LT(relative_to_rest_stiffness(corrected_block(hessian, s)), 0) << "edge Hessian";
  }
  // Inside, the two continuations agree, and N is continuous across the edge.
  const Vec3 inside(1.1, 1.0, 0.95);
  EXPECT_EQ(bounded.elastic_correction(inside), hessian.elastic_correction(inside));
  const Vec3 just_outside(1.0, 0.95, 0.9 - 1e-9);
  EXPECT_LE((bounded.elastic_correction(just_outside) - hessian.elastic_correction(c)).norm(),
      1e-6 * hessian.elastic_correction(c).norm());
  // A correction whose edge keeps more than β of K₀ is continued with its whole edge Hessian.
  const RbfCorrection mild_hessian = trusted_energy_correction(Continuation::edge_hessian);
  const RbfCorrection mild = trusted_energy_correction(Continuation::bounded_softening);
  mild_hessian.correction_gradient(c, Vec3::Zero(), edge, unused);
  ASSERT_GT(relative_to_rest_stiffness(k0 + edge), beta) << "the test needs a stable edge";
  for (const Vec3& s : { Vec3(1.0, 0.95, 0.6), Vec3(1.5, 1.0, 0.95) })
    EXPECT_EQ(mild.elastic_correction(s), mild_hessian.elastic_correction(s));
}

TEST(RbfCorrectionEnergy, RejectsAnInvalidTrustedInterval) {
  RbfCorrection::Parameters p = energy_correction().parameters();
  p.trusted.min = 1.2;
  p.trusted.max = 0.9;
  EXPECT_THROW(RbfCorrection { p }, InputError);
  p.trusted = trusted_interval(Continuation::bounded_softening);
  EXPECT_NO_THROW(RbfCorrection { p });
  p.trusted.kept_stiffness = 1.5;
  EXPECT_THROW(RbfCorrection { p }, InputError) << "β beyond 1";
  p.trusted.kept_stiffness = 0.5;
  p.trusted.nominal_stiffness(0, 0) = -1;
  EXPECT_THROW(RbfCorrection { p }, InputError) << "K₀ not positive definite";
  p.trusted.nominal_stiffness.setZero();
  EXPECT_THROW(RbfCorrection { p }, InputError) << "bounded without K₀";
  p.trusted = trusted_interval(Continuation::smooth_clamp);
  EXPECT_NO_THROW(RbfCorrection { p });
  p.trusted.clamp_width = 0;
  EXPECT_THROW(RbfCorrection { p }, InputError) << "no transition";
  p.trusted.clamp_width = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(RbfCorrection { p }, InputError) << "NaN width";
  RbfCorrection::Parameters stress = test_parameters(0.03);
  stress.trusted.max = 1.2;
  EXPECT_THROW(RbfCorrection { stress }, InputError) << "stress kernels have no energy";
}

namespace {

/// energy_correction() trusted in [0.9, 1.2], continued by a smooth form (w = 0.1).
RbfCorrection clamped_correction(Continuation continuation) {
  RbfCorrection::Parameters p = energy_correction().parameters();
  p.trusted = trusted_interval(continuation);
  p.trusted.clamp_width = 0.1;
  return RbfCorrection(std::move(p));
}

/// Far beyond, in the transition, at a tie beyond, and beyond both ends at once; none at the
/// transition's far end max + w, where the third derivative of φ jumps and central differences
/// lose their order.
const std::vector<Vec3> k_clamped_states { Vec3(1.6, 1.0, 0.95), Vec3(1.25, 1.02, 0.95),
  Vec3(1.24, 1.24, 0.92), Vec3(1.4, 1.33, 0.6), Vec3(0.85, 1.1, 1.6), Vec3(1.8, 1.01, 0.99),
  Vec3(1.28, 0.88, 1.05) };

const Continuation k_smooth_forms[] { Continuation::smooth_clamp, Continuation::smooth_expansion };

} // namespace

TEST(RbfCorrectionEnergy, TheSmoothFormsAreExactEnergiesEverywhere) {
  // ΔΨ(φ(σ)) plus the terms in the distances beyond: N is its gradient and the tangent N's
  // derivative, symmetric, at every state beyond the interval, mixed ones included (stretches
  // inside and outside at once), beyond both ends.
  for (const Continuation continuation : k_smooth_forms)
    for (const Vec3& s : k_clamped_states) {
      SCOPED_TRACE(
          testing::Message() << continuation_name(continuation) << ", stretches " << s.transpose());
      const RbfCorrection n = clamped_correction(continuation);
      expect_stress_is_energy_gradient(n, s);
      // Beyond both ends every stretch is saturated and the tangent is zero: its differences are
      // round-off, ~1e-16 |N| / h ≈ 1e-8 Pa: the floor 1e7 Pa allows 1 Pa of error wherever the
      // tangent is smaller (elsewhere it is ~1e4–1e6 Pa).
      expect_gradient_matches_fd(n, s, Vec3::Zero(), 1e-7, 1e7);
      Mat3 ds, dr;
      n.correction_gradient(s, Vec3::Zero(), ds, dr);
      EXPECT_LE((ds - ds.transpose()).norm(), 1e-10 * ds.norm()) << ds;
    }
}

TEST(RbfCorrectionEnergy, TheSmoothExpansionContinuesAQuadraticEnergyExactly) {
  // ΔΨ = a/2 Σ(σᵢ − 1)² + b Σ_{i<j}(σᵢ − 1)(σⱼ − 1) (the linear tail alone, no kernel): its
  // second-order expansion is itself, so beyond the trusted stretches the smooth expansion must
  // give the formula's stress and stiffness in the transition, far beyond, in mixed states and
  // beyond both ends. The smooth clamp (expanded at the end point, uncoupled) does not.
  RbfCorrection::Parameters p = energy_correction().parameters();
  p.weights.setZero();
  p.quadratic.setZero();
  p.neo_hookean.setZero();
  p.constant = 0;
  p.own_slope = 3e4;
  p.other_slope = 1e4;
  const RbfCorrection formula(p);
  p.trusted = trusted_interval(Continuation::smooth_expansion);
  const RbfCorrection n(std::move(p));
  std::vector<Vec3> states = k_clamped_states;
  states.insert(
      states.end(), { Vec3(1.23, 1.0, 0.95), Vec3(1.28, 0.88, 1.05), Vec3(0.82, 0.85, 1.1) });
  for (const Vec3& s : states) {
    SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
    Mat3 ds, dr, h;
    const Vec3 stress = n.correction_with_gradient(s, Vec3::Zero(), ds, dr);
    const Vec3 expected = formula.correction_with_gradient(s, Vec3::Zero(), h, dr);
    EXPECT_LE((stress - expected).norm(), 1e-9 * expected.norm() + 1e-9);
    EXPECT_LE((ds - h).norm(), 1e-9 * h.norm());
    EXPECT_NEAR(n.elastic_energy(s), formula.elastic_energy(s), 1e-9 * 3e4);
  }
  RbfCorrection::Parameters q = formula.parameters();
  q.trusted = trusted_interval(Continuation::smooth_clamp);
  const RbfCorrection clamp(std::move(q));
  Mat3 ds, dr;
  clamp.correction_with_gradient(Vec3(1.25, 1.0, 1.0), Vec3::Zero(), ds, dr); // x = ½
  // Its φ''-term and its expansion at the end point leave 0.78 a there (0.78–1.16 a across it).
  EXPECT_LT(ds(0, 0), 0.85 * 3e4) << "the smooth clamp keeps the stiffness in the transition";
}

TEST(RbfCorrectionEnergy, TheEdgeExpansionsTangentIsNotTheirStressDerivativeInMixedStates) {
  // What the smooth clamp fixes: beyond one end with the other stretches inside, the expansion
  // N(c) + H(c)(σ − c) moves its point c with those stretches, so ∂N/∂σ has third derivatives of
  // ΔΨ times the distance beyond the end, which its tangent H(c) leaves out: the stretch that
  // Newton's matrix and the stability check see is not the stress field's.
  const RbfCorrection n = trusted_energy_correction(Continuation::bounded_softening);
  const Vec3 s(1.8, 1.01, 0.97);
  Mat3 ds, dr;
  n.correction_gradient(s, Vec3::Zero(), ds, dr);
  Mat3 fd;
  const double h = 1e-6;
  for (int j = 0; j < 3; ++j) {
    Vec3 up = s, down = s;
    up[j] += h;
    down[j] -= h;
    fd.col(j) = (n.elastic_correction(up) - n.elastic_correction(down)) / (2 * h);
  }
  EXPECT_GT((fd - ds).norm(), 0.1 * ds.norm()) << "tangent\n" << ds << "\nN's derivative\n" << fd;
}

TEST(RbfCorrectionEnergy, FarBeyondTheSmoothFormsContinueTheEndsStressAndStiffness) {
  const RbfCorrection unbounded = energy_correction();
  // Beyond max + w along σ₁: N₁ is the end's stress g, stiffness k and (smooth_expansion)
  // coupling l continued from e = (max + w/2, 1, 1), the formula's N₁, ∂N₁/∂σ₁ and ∂N₁/∂σ₂ there
  // (k above the floor for this correction): N₁ = g + l (σ₂ − 1 + σ₃ − 1) + k (σ₁ − 1.25). The
  // other stretches see the formula at (max + w/2, σ₂, σ₃) plus l (σ₁ − 1.25). smooth_clamp
  // keeps the uniaxial part (l = 0).
  Mat3 end_hessian, unused;
  const double g = unbounded.correction_with_gradient(
      trusted_interval(Continuation::smooth_clamp).end_point(true), Vec3::Zero(), end_hessian,
      unused)[0];
  const double k = end_hessian(0, 0);
  ASSERT_GT(std::abs(end_hessian(0, 1)), 1e-3 * std::abs(k)) << "the test needs a coupling";
  const Mat3 k0 = bounded_nominal().principal_stress_derivative(Vec3::Ones());
  ASSERT_GT(k, -0.5 * (k0(0, 0) - k0(0, 1))) << "the test needs an end above the floor";
  for (const Continuation continuation : k_smooth_forms) {
    const RbfCorrection n = clamped_correction(continuation);
    // Inside: the formula itself.
    const Vec3 inside(1.1, 1.0, 0.95);
    EXPECT_EQ(n.elastic_correction(inside), unbounded.elastic_correction(inside));
    const double l = continuation == Continuation::smooth_expansion ? end_hessian(0, 1) : 0;
    for (const double s1 : { 1.31, 1.6, 3.0 }) {
      SCOPED_TRACE(testing::Message() << continuation_name(continuation) << ", σ₁ " << s1);
      const Vec3 s(s1, 1.02, 0.97);
      const double d = s1 - 1.25;
      Mat3 ds;
      const Vec3 stress = n.correction_with_gradient(s, Vec3::Zero(), ds, unused);
      const Vec3 at_phi = unbounded.elastic_correction(Vec3(1.25, 1.02, 0.97));
      const double scale = std::abs(g) + std::abs(k) + std::abs(end_hessian(0, 1)) + at_phi.norm();
      EXPECT_NEAR(stress[0], g + l * (0.02 - 0.03) + k * d, 1e-12 * scale);
      EXPECT_NEAR(stress[1], at_phi[1] + l * d, 1e-12 * scale);
      EXPECT_NEAR(stress[2], at_phi[2] + l * d, 1e-12 * scale);
      EXPECT_NEAR(ds(0, 0), k, 1e-12 * std::abs(k));
      for (int j = 1; j < 3; ++j) {
        EXPECT_NEAR(ds(0, j), l, 1e-12 * scale);
        EXPECT_NEAR(ds(j, 0), l, 1e-12 * scale);
      }
      // So the twist of the two stretches inside stays the formula's there, however far σ₁ goes
      // (an expansion at the moving edge point c adds third derivatives of ΔΨ times the
      // distance).
      Mat3 h;
      unbounded.correction_gradient(Vec3(1.25, 1.02, 0.97), Vec3::Zero(), h, unused);
      EXPECT_LE(
          (ds.bottomRightCorner<2, 2>() - h.bottomRightCorner<2, 2>()).norm(), 1e-9 * h.norm());
      // Δα₁ is the data's near the edge too, not its tails' far beyond.
      EXPECT_EQ(n.stiffness_damping(s), unbounded.stiffness_damping(Vec3(1.25, 1.02, 0.97)));
    }
    // C² at both ends of the transition: the tangent is continuous at max and at max + w.
    for (const double edge : { 1.2, 1.3 }) {
      SCOPED_TRACE(testing::Message() << continuation_name(continuation) << ", edge " << edge);
      Mat3 below, above;
      const double step = 1e-7;
      n.correction_gradient(Vec3(edge - step, 1.0, 0.95), Vec3::Zero(), below, unused);
      n.correction_gradient(Vec3(edge + step, 1.0, 0.95), Vec3::Zero(), above, unused);
      EXPECT_LE((above - below).norm(), 1e-4 * below.norm());
    }
  }
}

TEST(RbfCorrectionEnergy, FarBeyondTheSmoothFormsTheCorrectedModelKeepsItsShearStiffness) {
  // A correction that removes more than the nominal's stiffness near the interval's lower end:
  // far beyond it, along the stretch beyond, the corrected corotated model keeps β of its rest
  // shear stiffness 2μ (the end stiffness at its floor; the smooth expansion's end Hessian is
  // bounded first as bounded_softening bounds it, which may leave it above), where the edge
  // Hessian's expansion is unstable.
  for (const Continuation continuation : k_smooth_forms) {
    SCOPED_TRACE(continuation_name(continuation));
    RbfCorrection::Parameters p = softening_correction(Continuation::edge_hessian).parameters();
    p.trusted = trusted_interval(continuation);
    const RbfCorrection n(std::move(p));
    const RbfCorrection hessian = softening_correction(Continuation::edge_hessian);
    const Mat3 k0 = bounded_nominal().principal_stress_derivative(Vec3::Ones());
    const double floor = -(1 - kKeptStiffness) * (k0(0, 0) - k0(0, 1));
    Mat3 end_hessian, unused;
    hessian.correction_gradient(
        n.parameters().trusted.end_point(false), Vec3::Zero(), end_hessian, unused);
    ASSERT_LT(end_hessian(0, 0), floor) << "the test needs an end below the floor";
    RbfCorrection::Parameters untrusted = n.parameters();
    untrusted.trusted = {};
    Mat3 formula_hessian; // at the end point, the formula's own
    RbfCorrection(std::move(untrusted))
        .correction_gradient(
            n.parameters().trusted.end_point(false), Vec3::Zero(), formula_hessian, unused);
    const double kept = continuation == Continuation::smooth_expansion
        ? std::max(n.parameters().trusted.continued_hessian(formula_hessian)(0, 0), floor)
        : floor;
    for (const Vec3& s : { Vec3(1.0, 0.95, 0.6), Vec3(1.0, 0.95, 0.4) }) {
      SCOPED_TRACE(testing::Message() << "stretches " << s.transpose());
      const CorrectedStress c = corrected_principal_stress(bounded_nominal(), &n, s, Vec3::Zero());
      const Mat3 k = bounded_nominal().principal_stress_derivative(s);
      EXPECT_NEAR(c.d_stretches(2, 2), k(2, 2) + kept, 1e-9 * k.norm());
      EXPECT_GT(c.d_stretches(2, 2), 0);
      const CorrectedStress e
          = corrected_principal_stress(bounded_nominal(), &hessian, s, Vec3::Zero());
      EXPECT_LT(e.d_stretches(2, 2), 0) << "the edge Hessian's expansion";
    }
  }
}
