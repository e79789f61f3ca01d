// NnCorrection (paper 000 §6.2, Eq. 1): agreement with a direct evaluation of the documented
// formula, exact gradients (finite differences), isotropy (permutation symmetry, equal outputs at
// equal stretches, a stress that does not depend on the SVD's frame and is continuous across a
// repeated stretch), parameter validation.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/material/principal_stress.hpp>

#include <support/bounded_hessian.hpp>
#include <support/finite_difference.hpp>

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// A 6 → 6 → 6 → 1 network (the paper's Fig. 5 widths) with random weights of unit size, inputs
/// standardised around rest with scales ~0.1 (stretches), 0.01 (half the squared stretch gap),
/// 0.5 1/s (rates) and 0.05 1/s (the gap-rate product), output ~1e3 Pa.
NnCorrection::Parameters test_parameters(const std::vector<int>& hidden = { 6, 6 }) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  NnCorrection::Parameters p;
  p.input_mean << 1.0, 2.0, 0.01, 0.0, 0.0, 0.0;
  p.input_scale << 0.1, 0.15, 0.01, 0.5, 0.8, 0.05;
  p.output_mean = 10;
  p.output_scale = 1.5e3;
  int in = 6;
  std::vector<int> widths = hidden;
  widths.push_back(1);
  for (int out : widths) {
    NnCorrection::Layer l;
    l.weight.resize(out, in);
    l.bias.resize(out);
    for (Eigen::Index i = 0; i < l.weight.size(); ++i)
      l.weight.data()[i] = g(rng) / std::sqrt(in);
    for (auto& b : l.bias)
      b = 0.3 * g(rng);
    p.layers.push_back(l);
    in = out;
  }
  return p;
}

/// The documented formula, evaluated with Eigen (allocating) and the view built from its
/// definition (directions taken cyclically, not sorted by index) as an independent reference.
Vec3 reference_output(const NnCorrection::Parameters& p, const Vec3& s, const Vec3& f) {
  Vec3 n;
  for (int k = 0; k < 3; ++k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    VecX x(6);
    x << s[k], s[a] + s[b], std::pow(s[a] - s[b], 2) / 2, f[k], f[a] + f[b],
        (s[a] - s[b]) * (f[a] - f[b]);
    x = (x - p.input_mean).cwiseQuotient(p.input_scale);
    for (std::size_t l = 0; l < p.layers.size(); ++l) {
      x = p.layers[l].weight * x + p.layers[l].bias;
      if (l + 1 < p.layers.size())
        x = x.unaryExpr([&](double z) { return activation_values(p.activation, z).f; });
    }
    n[k] = p.output_mean + p.output_scale * x[0];
  }
  return n;
}

/// P = U diag(N(σ, ḟ)) Vᵀ [Pa] of a correction alone (the nominal P̂ is isotropic and plays no
/// part in the frame question) at F, Ḟ, for a given principal frame of F.
Mat3 corrected_piola(const Correction& n, const PrincipalFrame& frame, const Mat3& F_rate) {
  return first_piola(frame, n.correction(frame.stretches, stretch_rates(frame, F_rate)));
}

Mat3 rotation(double angle, const Vec3& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

} // namespace

TEST(NnCorrection, MatchesTheDocumentedFormula) {
  // The loops and Eigen's products sum in different orders, and eᶻ − 1 vs expm1 differ by
  // ~1e-16: agreement to 1e-12 relative of ~1e3 Pa. Unsorted inputs: every view is exercised.
  const auto p = test_parameters();
  const NnCorrection n(p);
  for (const Vec3& s : { Vec3(1.2, 1.05, 0.9), Vec3(0.9, 1.25, 1.02), Vec3(1.0, 0.8, 1.1) }) {
    const Vec3 f(0.3, -0.7, 0.2);
    const Vec3 expected = reference_output(p, s, f);
    EXPECT_LT((n.correction(s, f) - expected).norm(), 1e-12 * expected.norm()) << s.transpose();
  }
  EXPECT_EQ(n.name(), "nn");
  // nn_input is the documented view, and swapping the other two directions leaves it unchanged.
  const Vec3 s(1.0, 2.0, 3.0), f(0.5, -1.0, 4.0);
  NnInput expected;
  expected << 1.0, 5.0, 0.5, 0.5, 3.0, (2.0 - 3.0) * (-1.0 - 4.0);
  EXPECT_EQ(nn_input(s, f, 0), expected);
  EXPECT_EQ(nn_input(Vec3(1.0, 3.0, 2.0), Vec3(0.5, 4.0, -1.0), 0), expected);
}

TEST(NnCorrection, GradientMatchesFiniteDifference) {
  // The network is smooth except where a pre-activation crosses 0 (ELU's second derivative
  // jumps there, the first does not). At these fixed states no crossing lies within the FD
  // stencil (4·1e-5), so the O(h⁴) truncation error is ~1e-12 relative and round-off in the
  // quotient of values ~1e3 Pa is ~1e-16·1e3/1e-5 ≈ 1e-8 Pa against gradients ~1e4: 1e-7 tolerance.
  for (const auto& hidden : { std::vector<int> { 6, 6 }, std::vector<int> { 12 },
           std::vector<int> { 32, 8, 5 }, std::vector<int> {} }) {
    const NnCorrection n(test_parameters(hidden));
    for (const Vec3& s : { Vec3(1.15, 0.97, 0.88), Vec3(0.9, 1.25, 1.02), Vec3(1.1, 0.95, -0.2) }) {
      for (const Vec3& r : { Vec3(0.3, -0.5, 0.1), Vec3(-1.2, 0.4, 0.9) }) {
        SCOPED_TRACE(testing::Message() << "hidden layers " << hidden.size() << " stretches "
                                        << s.transpose() << " rates " << r.transpose());
        Mat3 ds, dr;
        n.correction_gradient(s, r, ds, dr);
        Eigen::MatrixXd J(3, 6);
        J << ds, dr;
        Eigen::VectorXd in(6);
        in << s, r;
        const FdFunction fn = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
          return n.correction(y.head<3>(), y.tail<3>());
        };
        expect_jacobian_matches(J, fn, in, 1e-7, 1e-5);
      }
    }
  }
}

TEST(NnCorrection, PermutationSymmetric) {
  const NnCorrection n(test_parameters());
  const Vec3 s(1.15, 0.97, 0.88), r(0.3, -0.5, 0.1);
  const Vec3 ns = n.correction(s, r);
  Mat3 ds, dr;
  n.correction_gradient(s, r, ds, dr);
  std::array<int, 3> perm { 0, 1, 2 };
  while (std::next_permutation(perm.begin(), perm.end())) {
    // N(Pσ, Pḟ) = P N(σ, ḟ) and the gradients permute on both sides. Exact: every direction
    // sees the same numbers (commutative sums, a squared difference and a product of two
    // swapped differences do not depend on the order of the other two).
    Eigen::PermutationMatrix<3> P;
    P.indices() << perm[0], perm[1], perm[2];
    const Vec3 ps = P * s, pr = P * r;
    EXPECT_EQ(n.correction(ps, pr), P * ns);
    Mat3 pds, pdr;
    n.correction_gradient(ps, pr, pds, pdr);
    EXPECT_EQ(pds, P * ds * P.transpose());
    EXPECT_EQ(pdr, P * dr * P.transpose());
  }
  // A clone evaluates identically.
  EXPECT_EQ(n.clone()->correction(s, r), ns);
}

TEST(NnCorrection, EqualStretchesGiveExactlyEqualOutputs) {
  // Both directions of a repeated stretch evaluate the same network on bit-identical inputs —
  // at zero rate (the elastic part) and at equal rates — whatever the other rate is.
  const NnCorrection n(test_parameters());
  for (const Vec3& s :
      { Vec3(1.1, 1.1, 0.9), Vec3(0.8, 1.2, 1.2), Vec3(1.05, 0.7, 1.05), Vec3::Ones().eval() }) {
    for (const Vec3& rates : { Vec3::Zero().eval(), Vec3(0.2, 0.2, 0.2), Vec3(0.4, 0.4, -0.3),
             Vec3(0.4, -0.3, 0.4), Vec3(-0.3, 0.4, 0.4) }) {
      const Vec3 out = n.correction(s, rates);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          if (s[i] == s[j] && rates[i] == rates[j]) {
            EXPECT_EQ(out[i], out[j])
                << "stretches " << s.transpose() << " rates " << rates.transpose();
          }
        }
      }
    }
  }
  // The outputs approach each other continuously as two stretches meet: Lipschitz, with
  // slopes ∂g/∂σ ~ output_scale/input_scale ~1e4–1e5 Pa.
  const Vec3 out = n.correction(Vec3(1.1 + 1e-7, 1.1, 0.9), Vec3::Zero());
  EXPECT_LT(std::abs(out[0] - out[1]), 1e-7 * 1e5);
}

TEST(NnCorrection, GradientIsContinuousAtEqualStretches) {
  // The inputs are smooth in σ (no max/min), so ∂N/∂σ has no kink where two stretches meet:
  // either side of σ₂ = σ₃ agrees with the value at the tie to O(h × curvature) — curvature
  // ~ output_scale/input_scale² ~1e7 Pa, so ~1 Pa for h = 1e-7 against gradients ~1e4–1e5.
  // A max/min view would jump by |∂g/∂max − ∂g/∂min| ~ the gradient itself.
  const NnCorrection n(test_parameters());
  const Vec3 r(0.3, -0.5, 0.1);
  const double h = 1e-7;
  Mat3 ds0, dr0, ds_plus, dr_plus, ds_minus, dr_minus;
  n.correction_gradient(Vec3(1.1, 1.0, 1.0), r, ds0, dr0);
  n.correction_gradient(Vec3(1.1, 1.0 + h, 1.0), r, ds_plus, dr_plus);
  n.correction_gradient(Vec3(1.1, 1.0, 1.0 + h), r, ds_minus, dr_minus);
  EXPECT_LT((ds_plus - ds0).norm(), 10.0) << ds0.norm();
  EXPECT_LT((ds_minus - ds0).norm(), 10.0) << ds0.norm();
  EXPECT_LT((dr_plus - dr0).norm(), 10.0) << dr0.norm();
  EXPECT_GT(ds0.norm(), 1e3); // the bound is meaningful
}

TEST(NnCorrection, StressIsContinuousAcrossARepeatedStretch) {
  const NnCorrection n(test_parameters());
  const Mat3 R = rotation(0.7, Vec3(1, 2, 3)), Q = rotation(-0.4, Vec3(-2, 1, 1));
  const Mat3 F_rate = (Mat3() << 0.3, -0.8, 0.2, 0.5, 0.1, -0.6, -0.4, 0.7, 0.9).finished();
  const auto F_at
      = [&](double t) { return Mat3(R * Vec3(1.1, 1 + t, 1 - t).asDiagonal() * Q.transpose()); };
  const double scale = 1.5e3; // |N| ~ output_scale

  // At the tie (σ₂ = σ₃ = 1) U and V are unique only up to a common rotation in the degenerate
  // plane. At zero rate the stress is the same for any such choice: round-off only (1e-12 of
  // |N|), whereas 3 independent outputs would differ by their fitting error.
  const PrincipalFrame frame = principal_frame(F_at(0));
  for (double angle : { 0.3, 1.0, 2.5 }) {
    PrincipalFrame turned = frame;
    const Mat3 G = rotation(angle, Vec3::UnitX());
    turned.U = frame.U * G;
    turned.V = frame.V * G;
    ASSERT_LT(
        (turned.U * turned.stretches.asDiagonal() * turned.V.transpose() - F_at(0)).norm(), 1e-12);
    EXPECT_LT(
        (corrected_piola(n, turned, Mat3::Zero()) - corrected_piola(n, frame, Mat3::Zero())).norm(),
        1e-12 * scale)
        << "angle " << angle;
  }

  // Along F(t) = R diag(1.1, 1 + t, 1 − t) Qᵀ with a generic rate Ḟ (ḟ₂ ≠ ḟ₃), σ₂ and σ₃ swap
  // at t = 0 and so do the SVD's columns. The stress is Lipschitz in t: the jump over
  // [−h, h] is ≤ 2h × slope (~1e5 Pa) — 2e-2 Pa for h = 1e-7. The same network fed the rates
  // ordered like the stretches (the rejected alternative) jumps by O(|N|) = O(1e3 Pa) there.
  const double h = 1e-7;
  const Mat3 before = corrected_piola(n, principal_frame(F_at(-h)), F_rate);
  const Mat3 after = corrected_piola(n, principal_frame(F_at(h)), F_rate);
  EXPECT_LT((after - before).norm(), 2 * h * 1e5);

  struct RatesOrderedByStretch final : Correction {
    const NnCorrection& net;
    explicit RatesOrderedByStretch(const NnCorrection& n)
        : net(n) { }
    std::string name() const override { return "sorted-rates"; }
    Vec3 correction(const Vec3& s, const Vec3& f) const override {
      Vec3 out;
      for (int k = 0; k < 3; ++k) {
        const int a = (k + 1) % 3, b = (k + 2) % 3, hi = s[b] > s[a] ? b : a, lo = hi == a ? b : a;
        NnInput x;
        x << s[k], s[hi], s[lo], f[k], f[hi], f[lo];
        out[k] = net.evaluate(x);
      }
      return out;
    }
    void correction_gradient(const Vec3&, const Vec3&, Mat3&, Mat3&) const override { }
    std::unique_ptr<Correction> clone() const override { return nullptr; }
  } sorted_rates(n);
  const Mat3 jump = corrected_piola(sorted_rates, principal_frame(F_at(h)), F_rate)
      - corrected_piola(sorted_rates, principal_frame(F_at(-h)), F_rate);
  EXPECT_GT(jump.norm(), 1e3 * (after - before).norm()) << "the test would not see a discontinuity";
}

TEST(NnCorrection, RejectsBadParameters) {
  const auto expect_error = [](NnCorrection::Parameters p, const std::string& where) {
    try {
      NnCorrection n(std::move(p));
      ADD_FAILURE() << "expected InputError at " << where;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), where) << e.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NO_THROW(NnCorrection { test_parameters() });
  {
    auto p = test_parameters();
    p.layers.clear();
    expect_error(p, "nn_correction.layers");
  }
  {
    auto p = test_parameters(std::vector<int>(NnCorrection::max_hidden_layers + 1, 2));
    expect_error(p, "nn_correction.layers");
  }
  {
    auto p = test_parameters();
    p.layers[0].weight = MatX::Ones(6, 5); // 5 inputs instead of 6
    expect_error(p, "nn_correction.layers[0].weight");
  }
  {
    auto p = test_parameters();
    p.layers[1].weight = MatX::Ones(6, 7); // does not chain to the 6-wide first layer
    expect_error(p, "nn_correction.layers[1].weight");
  }
  {
    auto p = test_parameters();
    p.layers[2].weight = MatX::Ones(3, 6); // 3 outputs (the old per-direction network)
    p.layers[2].bias = VecX::Ones(3);
    expect_error(p, "nn_correction.layers[2].weight");
  }
  {
    auto p = test_parameters();
    p.layers[1].bias = VecX::Ones(5);
    expect_error(p, "nn_correction.layers[1].bias");
  }
  {
    auto p = test_parameters({ NnCorrection::max_width + 1 });
    expect_error(p, "nn_correction.layers[0].weight");
  }
  {
    auto p = test_parameters();
    p.layers[1].weight(2, 3) = nan;
    expect_error(p, "nn_correction.layers[1].weight");
  }
  {
    auto p = test_parameters();
    p.layers[2].bias[0] = std::numeric_limits<double>::infinity();
    expect_error(p, "nn_correction.layers[2].bias");
  }
  {
    auto p = test_parameters();
    p.input_mean[4] = nan;
    expect_error(p, "nn_correction.input_mean");
  }
  {
    auto p = test_parameters();
    p.input_scale[2] = 0;
    expect_error(p, "nn_correction.input_scale");
  }
  {
    auto p = test_parameters();
    p.output_scale = -1;
    expect_error(p, "nn_correction.output_scale");
  }
  {
    auto p = test_parameters();
    p.output_mean = nan;
    expect_error(p, "nn_correction.output_mean");
  }
}

// ---- energy network (NnKind::Energy) --------------------------------------------------------

namespace {

/// An energy network p → ΔΨ with random weights of unit size (hidden widths `hidden`), inputs
/// standardised like a learning run's power sums (p₁ ~ 0.1, p₂ ~ 0.01, p₃ ~ 10⁻³), output ~10³
/// J/m³, and a polynomial of the size of a 20 % Lamé error.
NnCorrection::Parameters energy_parameters(
    const std::vector<int>& hidden, Activation activation = Activation::Squareplus) {
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  NnCorrection::Parameters p;
  p.kind = NnKind::Energy;
  p.activation = activation;
  p.input_mean = Vec3(0.0, 0.01, 0.0);
  p.input_scale = Vec3(0.1, 0.01, 0.001);
  p.output_mean = 3;
  p.output_scale = 1e3;
  p.polynomial << 50, -2e4, -4e4, 1e4, 2e4, -3e4;
  int in = 3;
  std::vector<int> widths = hidden;
  widths.push_back(1);
  for (int out : widths) {
    NnCorrection::Layer l;
    l.weight.resize(out, in);
    l.bias.resize(out);
    for (Eigen::Index i = 0; i < l.weight.size(); ++i)
      l.weight.data()[i] = g(rng) / std::sqrt(in);
    for (auto& b : l.bias)
      b = 0.3 * g(rng);
    p.layers.push_back(l);
    in = out;
  }
  return p;
}

/// The architectures that run each evaluation path: the fixed-size kernels (8-8, 6-6), the
/// general loops (5-7, three layers, one layer) and no hidden layer.
const std::vector<std::vector<int>> k_energy_architectures { { 8, 8 }, { 6, 6 }, { 5, 7 },
  { 6, 4, 3 }, { 12 }, {} };

const std::vector<Vec3> k_network_energy_states { Vec3(1.12, 0.97, 0.9), Vec3(0.85, 1.2, 1.03),
  Vec3(1.0, 1.0, 1.0), Vec3(1.3, 0.7, 0.95) };

} // namespace

TEST(NnEnergyCorrection, StressIsTheGradientOfTheEnergy) {
  // N = ∇ΔΨ against 4th-order central differences of elastic_energy (computed by an independent
  // forward pass). The inputs vary on the scale ε = energy_input_epsilon (0.05) near rest, so
  // the O(h⁴) truncation is ~(h/ε)⁴ × the input scales' 1/s: h = 1e-6 makes it negligible;
  // round-off ~1e-16·1e4/1e-6 ≈ 1e-6 Pa against N ~ 10³–10⁴ Pa. 1e-6 relative.
  for (Activation a : { Activation::Squareplus, Activation::Softplus, Activation::Tanh,
           Activation::Sigmoid, Activation::Elu }) {
    for (const auto& hidden : k_energy_architectures) {
      const NnCorrection n(energy_parameters(hidden, a));
      for (const Vec3& s : k_network_energy_states) {
        SCOPED_TRACE(testing::Message() << to_string(a) << ", " << hidden.size()
                                        << " hidden layers, stretches " << s.transpose());
        const Eigen::VectorXd N = n.correction(s, Vec3(0.4, -1, 2));
        const auto psi = [&](const Eigen::VectorXd& y) { return n.elastic_energy(y); };
        const FdFunction grad = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
          return Eigen::VectorXd::Constant(1, psi(y));
        };
        expect_jacobian_matches(N.transpose(), grad, s, 1e-6, 1e-6);
      }
    }
  }
}

TEST(NnEnergyCorrection, TangentIsSymmetricAndMatchesFiniteDifferences) {
  // ∂N/∂σ = ∇²ΔΨ: symmetric bit for bit, and equal to central differences of N. Smooth
  // activations only (ELU's f'' jumps at 0; a crossing inside the stencil would break the FD).
  // The inputs' scale ε near rest and the third input's scale 10⁻³ make the higher
  // derivatives large: h = 2e-6 keeps the O(h⁴) truncation below 1e-8 relative; round-off
  // ~1e-16·1e5/2e-6 ≈ 1e-5 Pa against tangents ~1e6 Pa.
  for (Activation a : { Activation::Squareplus, Activation::Softplus, Activation::Tanh }) {
    for (const auto& hidden : k_energy_architectures) {
      const NnCorrection n(energy_parameters(hidden, a));
      for (const Vec3& s : k_network_energy_states) {
        SCOPED_TRACE(testing::Message() << to_string(a) << ", " << hidden.size()
                                        << " hidden layers, stretches " << s.transpose());
        Mat3 ds, dr;
        const Vec3 N = n.correction_with_gradient(s, Vec3(0.4, -1, 2), ds, dr);
        EXPECT_EQ(N, n.correction(s, Vec3::Zero())); // one function, rates ignored
        EXPECT_EQ(ds, ds.transpose());
        EXPECT_TRUE(dr.isZero(0));
        const FdFunction fn = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
          return n.correction(y, Vec3::Zero());
        };
        expect_jacobian_matches(ds, fn, s, 1e-6, 2e-6);
      }
    }
  }
  EXPECT_FALSE(NnCorrection(energy_parameters({ 8, 8 })).depends_on_rates());
}

TEST(NnEnergyCorrection, IsotropicWithExactlyEqualComponentsAtEqualStretches) {
  for (const auto& hidden : k_energy_architectures) {
    const NnCorrection n(energy_parameters(hidden));
    // Equal stretches, bit-identical components of N and of the tangent's rows, so P = U diag(P̂ +
    // N) Vᵀ does not depend on the SVD's frame there.
    for (const Vec3& s :
        { Vec3(1.1, 1.1, 0.9), Vec3(0.95, 1.2, 1.2), Vec3(1.05, 0.8, 1.05), Vec3(1.0, 1.0, 1.0) }) {
      Mat3 ds, dr;
      const Vec3 N = n.correction_with_gradient(s, Vec3::Zero(), ds, dr);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (i != j && s[i] == s[j]) {
            EXPECT_EQ(N[i], N[j]);
            EXPECT_EQ(ds(i, i), ds(j, j));
          }
    }
    // Permuting the stretches permutes N and the tangent.
    const Vec3 s(1.12, 0.97, 0.9);
    Mat3 ds, dr;
    const Vec3 N = n.correction_with_gradient(s, Vec3::Zero(), ds, dr);
    Eigen::PermutationMatrix<3> P(Eigen::Vector3i(2, 0, 1));
    Mat3 ds_p, dr_p;
    const Vec3 N_p = n.correction_with_gradient(P * s, Vec3::Zero(), ds_p, dr_p);
    EXPECT_LE((N_p - P * N).cwiseAbs().maxCoeff(), 1e-12 * N.cwiseAbs().maxCoeff());
    EXPECT_LE(
        (ds_p - P * ds * P.transpose()).cwiseAbs().maxCoeff(), 1e-12 * ds.cwiseAbs().maxCoeff());
  }
}

TEST(NnEnergyCorrection, PolynomialAloneIsItsAnalyticEnergy) {
  // With the MLP's output weights zero, ΔΨ = cᵀ m(p) + b: N is the polynomial's gradient,
  // written out here from m = (p₁, p₁², p₂, p₁³, p₁p₂, p₃).
  NnCorrection::Parameters p = energy_parameters({ 8, 8 });
  p.layers.back().weight.setZero();
  const NnCorrection n(p);
  const auto& c = p.polynomial;
  const Vec3 s(1.12, 0.97, 0.9), e = s - Vec3::Ones();
  const double p1 = e.sum(), p2 = e.squaredNorm();
  Vec3 expected;
  for (int i = 0; i < 3; ++i)
    expected[i] = c[0] + 2 * c[1] * p1 + 2 * c[2] * e[i] + 3 * c[3] * p1 * p1
        + c[4] * (p2 + 2 * p1 * e[i]) + 3 * c[5] * e[i] * e[i];
  EXPECT_LE(
      (n.correction(s, Vec3::Zero()) - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.norm());
}

TEST(NnEnergyCorrection, RejectsBadParameters) {
  const auto expect_error = [](NnCorrection::Parameters p, const std::string& where) {
    try {
      NnCorrection n(std::move(p));
      ADD_FAILURE() << "expected an error naming " << where;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), where) << e.what();
    }
  };
  {
    auto p = energy_parameters({ 8, 8 });
    p.input_mean = VecX::Zero(6); // a stress network's standardisation
    expect_error(p, "nn_correction.input_mean");
  }
  {
    auto p = energy_parameters({ 8, 8 });
    p.layers[0].weight = MatX::Ones(8, 6);
    expect_error(p, "nn_correction.layers[0].weight");
  }
  {
    auto p = test_parameters();
    p.polynomial[2] = 1; // only an energy network has one
    expect_error(p, "nn_correction.polynomial");
  }
  {
    auto p = energy_parameters({ 8, 8 });
    p.polynomial[0] = std::numeric_limits<double>::quiet_NaN();
    expect_error(p, "nn_correction.polynomial");
  }
  EXPECT_THROW(NnCorrection(test_parameters()).elastic_energy(Vec3::Ones()), InputError);
  EXPECT_THROW(NnCorrection(energy_parameters({ 8, 8 })).evaluate(NnInput::Zero()), InputError);
}

TEST(NnCorrection, StressNetworkActivationsHaveExactGradients) {
  // The fixed-size (6-6, 8-8) and general paths with each activation, against FD.
  for (Activation a : { Activation::Elu, Activation::Sigmoid, Activation::Softplus,
           Activation::Tanh, Activation::Squareplus }) {
    for (const auto& hidden :
        { std::vector<int> { 6, 6 }, std::vector<int> { 8, 8 }, std::vector<int> { 7, 5 } }) {
      auto p = test_parameters(hidden);
      p.activation = a;
      const NnCorrection n(p);
      const Vec3 s(1.15, 0.97, 0.88), r(0.3, -0.5, 0.1);
      SCOPED_TRACE(testing::Message() << to_string(a) << ", width " << hidden[0]);
      Mat3 ds, dr;
      const Vec3 N = n.correction_with_gradient(s, r, ds, dr);
      EXPECT_LE((N - reference_output(p, s, r)).cwiseAbs().maxCoeff(), 1e-9 * N.norm());
      Eigen::MatrixXd J(3, 6);
      J << ds, dr;
      Eigen::VectorXd in(6);
      in << s, r;
      const FdFunction fn = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
        return n.correction(y.head<3>(), y.tail<3>());
      };
      expect_jacobian_matches(J, fn, in, 1e-7, 1e-5);
    }
  }
}

TEST(NnCorrectionEnergy, BeyondItsTrustedStretchesItKeepsTheStiffnessOfTheEdge) {
  // The same continuation as an RBF teacher's (material/trusted_stretches.hpp): the network
  // itself inside, its second-order expansion at the nearest trusted point outside, with the
  // edge's Hessian H (edge_hessian) or H bounded below by K₀ + H ⪰ β K₀ (bounded_softening; K₀
  // a stiffness the network's edge Hessians fall below, so that the bound is active).
  const NnCorrection unbounded(energy_parameters({ 8, 8 }));
  NnCorrection::Parameters p = energy_parameters({ 8, 8 });
  for (const Continuation continuation :
      { Continuation::edge_hessian, Continuation::bounded_softening }) {
    p.trusted = { 0.9, 1.2, continuation };
    bool bound_active = false;
    for (const Vec3& s : { Vec3(1.5, 1.0, 0.95), Vec3(0.7, 1.1, 1.6) }) {
      SCOPED_TRACE(testing::Message()
          << "stretches " << s.transpose() << ", continuation " << static_cast<int>(continuation));
      const Vec3 c = s.cwiseMax(0.9).cwiseMin(1.2);
      Mat3 edge, ds, unused;
      unbounded.correction_gradient(c, Vec3::Zero(), edge, unused);
      // K₀ = a multiple of I + 1 1ᵀ of which the edge Hessian removes 2/3 where it softens.
      const Mat3 shape = Mat3::Identity() + Mat3::Ones();
      const double scale = std::max(
          1.0, -1.5 * Eigen::GeneralizedSelfAdjointEigenSolver<Mat3>(edge, shape).eigenvalues()(0));
      p.trusted.nominal_stiffness = scale * shape;
      const NnCorrection n(p);
      EXPECT_EQ(n.correction(Vec3(1.1, 1.0, 0.95), Vec3::Zero()),
          unbounded.correction(Vec3(1.1, 1.0, 0.95), Vec3::Zero()));
      Mat3 h = edge;
      if (continuation == Continuation::bounded_softening) {
        const Mat3& k0 = p.trusted.nominal_stiffness;
        const double beta = p.trusted.kept_stiffness;
        bound_active = bound_active
            || Eigen::GeneralizedSelfAdjointEigenSolver<Mat3>(edge, k0).eigenvalues().minCoeff()
                < beta - 1;
        h = bounded_hessian(edge, k0, beta);
      }
      const Vec3 expected = unbounded.correction(c, Vec3::Zero()) + h * (s - c);
      const Vec3 got = n.correction_with_gradient(s, Vec3::Zero(), ds, unused);
      EXPECT_LE((got - expected).norm(), 1e-10 * expected.norm());
      EXPECT_LE((n.correction(s, Vec3::Zero()) - expected).norm(), 1e-10 * expected.norm());
      EXPECT_LE((ds - h).norm(), 1e-10 * edge.norm());
    }
    EXPECT_EQ(bound_active, continuation == Continuation::bounded_softening);
  }
  p.trusted = { 0.9, 1.2, Continuation::edge_hessian };
  const NnCorrection n(p);
  // Where every stretch is beyond the same end, N is the gradient of the continued energy.
  const Vec3 s(1.5, 1.35, 1.25);
  Eigen::MatrixXd stress(1, 3);
  stress.row(0) = n.correction(s, Vec3::Zero()).transpose();
  const FdFunction energy = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(1, n.elastic_energy(y.head<3>()));
  };
  expect_jacobian_matches(stress, energy, Eigen::VectorXd(s), 1e-7, 1e-4);
  NnCorrection::Parameters stress_network = test_parameters();
  stress_network.trusted = { 0.9, 1.2 };
  EXPECT_THROW(NnCorrection { stress_network }, InputError);
}

TEST(NnCorrectionEnergy, TheSmoothFormsAreExactEnergiesBeyondTheirTrustedStretches) {
  // An energy network continued by the smooth clamp or the smooth expansion: in mixed, transition
  // and saturated states its stress is the energy's gradient and its tangent the stress's
  // derivative (central differences), symmetric; inside it is the network itself.
  const NnCorrection unbounded(energy_parameters({ 8, 8 }));
  for (const auto continuation : { Continuation::smooth_clamp, Continuation::smooth_expansion })
    for (const Vec3& s : { Vec3(1.6, 1.0, 0.95), Vec3(1.25, 1.02, 0.95), Vec3(0.85, 1.1, 1.6),
             Vec3(1.35, 0.83, 1.21) }) {
      SCOPED_TRACE(
          testing::Message() << continuation_name(continuation) << ", stretches " << s.transpose());
      NnCorrection::Parameters p = energy_parameters({ 8, 8 });
      p.trusted = { 0.9, 1.2, continuation };
      p.trusted.nominal_stiffness = 1e4 * (Mat3::Identity() + Mat3::Ones());
      const NnCorrection n(p);
      EXPECT_EQ(n.correction(Vec3(1.1, 1.0, 0.95), Vec3::Zero()),
          unbounded.correction(Vec3(1.1, 1.0, 0.95), Vec3::Zero()));
      Eigen::MatrixXd stress(1, 3);
      stress.row(0) = n.correction(s, Vec3::Zero()).transpose();
      const FdFunction energy = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
        return Eigen::VectorXd::Constant(1, n.elastic_energy(y.head<3>()));
      };
      expect_jacobian_matches(stress, energy, Eigen::VectorXd(s), 1e-7, 1e-4);
      Mat3 ds, unused;
      n.correction_with_gradient(s, Vec3::Zero(), ds, unused);
      const FdFunction field = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
        return n.correction(y.head<3>(), Vec3::Zero());
      };
      expect_jacobian_matches(ds, field, Eigen::VectorXd(s), 1e-6, 1e-5);
      EXPECT_LE((ds - ds.transpose()).norm(), 1e-10 * ds.norm());
    }
}
