// NnCorrection (paper 000 §6.2, Eq. 1): exact gradients (finite differences), permutation
// symmetry, agreement with a direct evaluation of the documented formula, parameter validation.
#include <elastolearn/core/error.hpp>
#include <elastolearn/material/nn_correction.hpp>

#include <support/finite_difference.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace elastolearn;
using namespace elastolearn::material;
using namespace elastolearn::test;

namespace {

/// A 6 → 6 → 6 → 3 network (the paper's Fig. 5) with random weights of unit size, inputs
/// standardised around rest with scales 0.1 (stretches) and 0.5 1/s (rates), outputs ~1e3 Pa.
NnCorrection::Parameters test_parameters(const std::vector<int>& hidden = { 6, 6 }) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  NnCorrection::Parameters p;
  p.input_mean << 1.0, 1.0, 1.0, 0.0, 0.0, 0.0;
  p.input_scale << 0.1, 0.1, 0.12, 0.5, 0.5, 0.4;
  p.output_mean = Vec3(10, -20, 5);
  p.output_scale = Vec3(1e3, 2e3, 1.5e3);
  int in = 6;
  std::vector<int> widths = hidden;
  widths.push_back(3);
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

/// The documented formula, evaluated with Eigen (allocating) as an independent reference.
Vec3 reference_output(const NnCorrection::Parameters& p, const Vec3& s, const Vec3& f) {
  VecX a(6);
  a << s, f;
  a = (a - p.input_mean).cwiseQuotient(p.input_scale);
  for (std::size_t k = 0; k < p.layers.size(); ++k) {
    a = p.layers[k].weight * a + p.layers[k].bias;
    if (k + 1 < p.layers.size())
      a = a.unaryExpr([](double z) { return z > 0 ? z : std::expm1(z); });
  }
  return p.output_mean + p.output_scale.cwiseProduct(a.head<3>());
}

} // namespace

TEST(NnCorrection, MatchesTheDocumentedFormula) {
  // Sorted inputs go straight into the network; the loops and Eigen's products sum in different
  // orders, and eᶻ − 1 vs expm1 differ by ~1e-16: agreement to 1e-12 relative of ~1e3 Pa.
  const auto p = test_parameters();
  const NnCorrection n(p);
  const Vec3 s(1.2, 1.05, 0.9), f(0.3, -0.7, 0.2);
  const Vec3 expected = reference_output(p, s, f);
  EXPECT_LT((n.correction(s, f) - expected).norm(), 1e-12 * expected.norm());
  EXPECT_EQ(n.name(), "nn");
}

TEST(NnCorrection, GradientMatchesFiniteDifference) {
  // The network is smooth except where a pre-activation crosses 0 (ELU's second derivative
  // jumps there, the first does not). At these fixed states no crossing lies within the FD
  // stencil (4·1e-5), so the O(h⁴) truncation error is ~1e-12 relative and round-off in the
  // quotient of values ~1e3 Pa is ~1e-16·1e3/1e-5 ≈ 1e-8 Pa against gradients ~1e4: 1e-7 tolerance.
  for (const auto& hidden : { std::vector<int> { 6, 6 }, std::vector<int> { 12 },
           std::vector<int> { 32, 8, 5 } }) {
    const NnCorrection n(test_parameters(hidden));
    for (const Vec3& s : { Vec3(1.15, 0.97, 0.88), Vec3(0.9, 1.25, 1.02), Vec3(1.1, 0.95, -0.2) }) {
      for (const Vec3& r : { Vec3(0.3, -0.5, 0.1), Vec3(-1.2, 0.4, 0.9) }) {
        SCOPED_TRACE(testing::Message() << "widths " << hidden.size() << " stretches "
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
  Eigen::Matrix3i perms;
  perms << 1, 0, 2, 2, 0, 1, 2, 1, 0;
  for (int k = 0; k < 3; ++k) {
    // N(Pσ, Pḟ) = P N(σ, ḟ) and the gradients permute on both sides. Exact: the network sees
    // the same sorted numbers.
    Eigen::PermutationMatrix<3> P;
    P.indices() = perms.row(k).transpose();
    const Vec3 ps = P.transpose() * s, pr = P.transpose() * r;
    EXPECT_EQ(n.correction(ps, pr), P.transpose() * ns);
    Mat3 pds, pdr;
    n.correction_gradient(ps, pr, pds, pdr);
    EXPECT_EQ(pds, P.transpose() * ds * P);
    EXPECT_EQ(pdr, P.transpose() * dr * P);
  }
  // A clone evaluates identically.
  EXPECT_EQ(n.clone()->correction(s, r), ns);
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
    p.layers[2].weight = MatX::Ones(2, 6); // 2 outputs instead of 3
    p.layers[2].bias = VecX::Ones(2);
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
    p.output_scale[1] = -1;
    expect_error(p, "nn_correction.output_scale");
  }
  {
    auto p = test_parameters();
    p.output_mean[0] = nan;
    expect_error(p, "nn_correction.output_mean");
  }
}
