// Elastic + damping force term: invariants and derivatives, on a small irregular bar.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/rbf_correction.hpp>
#include <elastolearn/material/spline_edited.hpp>
#include <elastolearn/material/stvk.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <support/finite_difference.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <random>

using namespace elastolearn;

namespace {

const material::Lame kLame = material::Lame::from_young_poisson(3e5, 0.4);

mesh::TetMesh small_bar() {
  return mesh::make_box_bar(Vec3(0.4, 0.1, 0.1), { 4, 1, 1 });
}

std::shared_ptr<const material::ElasticModel> model(int which) {
  if (which == 0)
    return std::make_shared<material::CorotatedModel>(kLame);
  if (which == 1)
    return std::make_shared<material::StVKModel>(kLame);
  if (which == 3)
    return std::make_shared<material::SplineEditedModel>(material::ElasticModelType::NeoHookean,
        kLame, material::SplineEditRegion::Tension,
        material::CubicSpline({ 1.0, 1.1, 1.3 }, { 1.0, 2.0, 2.5 }, "tension"));
  return std::make_shared<material::NeoHookeanModel>(kLame);
}

const char* model_name(int which) {
  static const char* names[] = { "Corotated", "StVK", "NeoHookean", "SplineEdited" };
  return names[which];
}

std::shared_ptr<const material::DampingModel> rayleigh(
    double alpha0, double alpha1, material::DampingTangent tangent) {
  auto damping = std::make_shared<material::RayleighDamping>(alpha0, alpha1);
  damping->set_tangent(tangent);
  return damping;
}

/// A deterministic velocity field of unit-scale entries.
VecX random_velocity(Eigen::Index size, unsigned seed) {
  VecX v(size);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  for (auto& vi : v)
    vi = n01(rng);
  return v;
}

/// A smooth, moderately large deformation (bend + twist + stretch), deterministic.
VecX deformed(const mesh::TetMesh& mesh, double amount) {
  VecX x = flatten(mesh.rest_positions());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3 X = mesh.rest_positions().row(v);
    x.segment<3>(3 * v) += amount
        * Vec3(0.3 * X.x() + 0.02 * u(rng), 0.5 * X.x() * X.x() + 0.02 * u(rng),
            0.2 * X.x() * X.y() + 0.02 * u(rng));
  }
  return x;
}

Mat3 rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Vec3::UnitX()) * Eigen::AngleAxisd(b, Vec3::UnitY())
      * Eigen::AngleAxisd(c, Vec3::UnitZ()))
      .toRotationMatrix();
}

VecX force_at(fem::ElasticForce& term, const VecX& x, const VecX& v) {
  VecX f = VecX::Zero(x.size());
  term.add_force({ x, v, 0.0 }, f);
  return f;
}

/// The assembled Jacobian c_x K + c_v D (unprojected) and the force at (x, v).
Eigen::MatrixXd jacobian_at(
    fem::ElasticForce& term, const VecX& x, const VecX& v, double c_x, double c_v, VecX& f) {
  const int n = static_cast<int>(x.size() / 3);
  fem::DofMap dofs(n, {});
  fem::SystemMatrix A(term.tets(), dofs);
  f = VecX::Zero(x.size());
  A.set_zero();
  term.add_force_and_jacobian({ x, v, 0.0 }, c_x, c_v, f, A);
  return Eigen::MatrixXd(A.matrix());
}

/// −K is the finite-difference Jacobian of the force at (x, v), and the elastic energy's gradient
/// is minus the force f there (central differences, h = 1e-6).
void expect_consistent_stiffness_and_energy(fem::ElasticForce& term, const VecX& x, const VecX& v,
    const Eigen::MatrixXd& K, const VecX& f) {
  test::expect_jacobian_matches(
      -K, [&](const VecX& y) { return force_at(term, y, v); }, x, 1e-6, 1e-6);
  const VecX g = test::fd_gradient([&](const VecX& y) { return term.elastic_energy(y); }, x, 1e-6);
  EXPECT_LT((g + f).cwiseAbs().maxCoeff(), 1e-6 * f.cwiseAbs().maxCoeff());
}

} // namespace

class ElasticForceTest : public ::testing::TestWithParam<int> { };

TEST_P(ElasticForceTest, ZeroAtRestAndUnderRigidMotion) {
  const auto mesh = small_bar();
  fem::ElasticForce term(mesh, { model(GetParam()), nullptr, nullptr, 1000 });
  const VecX X = flatten(mesh.rest_positions());
  const VecX zero = VecX::Zero(X.size());
  // Force scale of this deformation state: E · area ≈ 3e5 · 0.01 = 3e3 N; 1e-9 relative.
  EXPECT_LT(force_at(term, X, zero).cwiseAbs().maxCoeff(), 1e-6);
  const Mat3 R = rotation(0.7, -1.1, 2.3);
  VecX x = X;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    x.segment<3>(3 * v) = R * X.segment<3>(3 * v) + Vec3(1, -2, 3);
  EXPECT_LT(force_at(term, x, zero).cwiseAbs().maxCoeff(), 1e-6);
}

TEST_P(ElasticForceTest, ForcesSumToZeroAndAreRotationCovariant) {
  const auto mesh = small_bar();
  fem::ElasticForce term(mesh, { model(GetParam()), nullptr, nullptr, 1000 });
  const VecX x = deformed(mesh, 0.5);
  const VecX f = force_at(term, x, VecX::Zero(x.size()));
  const double scale = f.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1.0);
  // Translation invariance ⇒ Σ f = 0; rotation invariance ⇒ Σ x × f = 0.
  Vec3 sum = Vec3::Zero(), torque = Vec3::Zero();
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    sum += f.segment<3>(3 * v);
    torque += x.segment<3>(3 * v).cross(f.segment<3>(3 * v));
  }
  EXPECT_LT(sum.norm(), 1e-10 * scale * mesh.num_vertices());
  EXPECT_LT(torque.norm(), 1e-10 * scale * mesh.num_vertices());
  const Mat3 R = rotation(0.3, 0.2, -0.9);
  VecX xr = x;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    xr.segment<3>(3 * v) = R * x.segment<3>(3 * v);
  const VecX fr = force_at(term, xr, VecX::Zero(x.size()));
  for (int v = 0; v < mesh.num_vertices(); ++v)
    EXPECT_LT((fr.segment<3>(3 * v) - R * f.segment<3>(3 * v)).norm(), 1e-9 * scale);
}

TEST_P(ElasticForceTest, ExactStiffnessIsMinusForceDerivative) {
  const auto mesh = small_bar();
  fem::ElasticForce term(mesh, { model(GetParam()), nullptr, nullptr, 1000 });
  term.set_project_tangent(false);
  fem::DofMap dofs(mesh.num_vertices(), {});
  fem::SystemMatrix A(mesh.tets(), dofs);
  const VecX x = deformed(mesh, 0.4);
  const VecX v = VecX::Zero(x.size());
  VecX f = VecX::Zero(x.size());
  A.set_zero();
  term.add_force_and_jacobian({ x, v, 0.0 }, 1.0, 0.0, f, A);
  const Eigen::MatrixXd K = Eigen::MatrixXd(A.matrix());
  expect_consistent_stiffness_and_energy(term, x, v, K, f);
}

TEST_P(ElasticForceTest, ProjectedStiffnessIsPositiveSemiDefinite) {
  const auto mesh = small_bar();
  fem::ElasticForce term(mesh, { model(GetParam()), nullptr, nullptr, 1000 });
  fem::DofMap dofs(mesh.num_vertices(), {});
  fem::SystemMatrix A(mesh.tets(), dofs);
  const VecX x = deformed(mesh, 1.5); // large enough that the exact tangent is indefinite
  VecX f = VecX::Zero(x.size());
  A.set_zero();
  term.add_force_and_jacobian({ x, VecX::Zero(x.size()), 0.0 }, 1.0, 0.0, f, A);
  const Eigen::MatrixXd K = Eigen::MatrixXd(A.matrix());
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-9 * K.cwiseAbs().maxCoeff());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(K);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-9 * eig.eigenvalues().maxCoeff());
}

INSTANTIATE_TEST_SUITE_P(Materials, ElasticForceTest, ::testing::Values(0, 1, 2),
    [](const auto& info) { return std::string(model_name(info.param)); });

class ExactRayleighDampingTest : public ::testing::TestWithParam<int> { };

TEST_P(ExactRayleighDampingTest, DampingForceIsMinusAlpha1TimesTheElasticForceDerivativeAlongV) {
  // Standard Rayleigh damping (Vega FEM, SOFA, Drake): f_d = −α₁ K(x) v with K = −∂f_el/∂x the
  // exact, unprojected stiffness, i.e. α₁ times the directional derivative of the elastic force
  // along v, here by central differences (error O(ε²) ≈ 1e-12 relative).
  const auto mesh = small_bar();
  const double alpha1 = 0.01;
  fem::ElasticForce damped(mesh,
      { model(GetParam()), nullptr, rayleigh(0, alpha1, material::DampingTangent::Exact), 1000 });
  fem::ElasticForce elastic(mesh, { model(GetParam()), nullptr, nullptr, 1000 });
  const VecX x = deformed(mesh, 0.3);
  const VecX v = random_velocity(x.size(), 11);
  const VecX zero = VecX::Zero(x.size());
  const VecX f_damping = force_at(damped, x, v) - force_at(damped, x, zero);
  const double eps = 1e-6;
  const VecX directional
      = (force_at(elastic, x + eps * v, zero) - force_at(elastic, x - eps * v, zero)) / (2 * eps);
  EXPECT_LE((f_damping - alpha1 * directional).norm(), 1e-6 * f_damping.norm());
  // The flip-free tangent is another stiffness on this deformed state (the check can fail).
  fem::ElasticForce flip_free(mesh,
      { model(GetParam()), nullptr, rayleigh(0, alpha1, material::DampingTangent::FlipFree),
          1000 });
  const VecX f_flip_free = force_at(flip_free, x, v) - force_at(flip_free, x, zero);
  EXPECT_GT((f_flip_free - alpha1 * directional).norm(), 1e-3 * f_damping.norm());
}

TEST_P(ExactRayleighDampingTest, NewtonsUnprojectedJacobianIsMinusTheVelocityDerivative) {
  const auto mesh = small_bar();
  fem::ElasticForce term(mesh,
      { model(GetParam()), nullptr, rayleigh(0.2, 0.01, material::DampingTangent::Exact), 1000 },
      fem::MassType::Consistent);
  term.set_project_tangent(false);
  const VecX x = deformed(mesh, 0.3);
  const VecX v = random_velocity(x.size(), 5);
  VecX f;
  test::expect_jacobian_matches(
      -jacobian_at(term, x, v, 0.0, 1.0, f), [&](const VecX& w) { return force_at(term, x, w); }, v,
      1e-7);
}

INSTANTIATE_TEST_SUITE_P(Materials, ExactRayleighDampingTest, ::testing::Values(0, 1, 2, 3),
    [](const auto& info) { return std::string(model_name(info.param)); });

TEST(RayleighDampingForce, Alpha0ScalesTheScenesMassMatrix) {
  // −α₀ M v with M lumped (ρ vol/4 per vertex) or consistent (ρ vol/20 (1 + δ_ab) I₃).
  const auto mesh = small_bar();
  const double alpha0 = 0.3, density = 1000;
  const VecX x = deformed(mesh, 0.2);
  const VecX v = random_velocity(x.size(), 9);
  const VecX zero = VecX::Zero(x.size());
  const auto rest = fem::precompute_rest_data(mesh);
  fem::DofMap all(mesh.num_vertices(), {});
  fem::SystemMatrix consistent(mesh.tets(), all);
  consistent.set_zero();
  consistent.add_element_blocks(fem::consistent_mass_blocks(rest, density));
  const VecX lumped = fem::lumped_dof_masses(
      fem::lumped_vertex_masses(mesh.tets(), rest, mesh.num_vertices(), density));
  for (auto mass : { fem::MassType::Lumped, fem::MassType::Consistent }) {
    fem::ElasticForce term(mesh,
        { model(0), nullptr, rayleigh(alpha0, 0, material::DampingTangent::Exact), density }, mass);
    const VecX f = force_at(term, x, v) - force_at(term, x, zero);
    const VecX expected = mass == fem::MassType::Lumped ? VecX(-alpha0 * lumped.cwiseProduct(v))
                                                        : VecX(-alpha0 * (consistent.matrix() * v));
    EXPECT_LE((f - expected).norm(), 1e-12 * expected.norm()) << fem::to_string(mass);
  }
}

TEST(RayleighDampingForce, DampingJacobianIsMinusVelocityDerivative) {
  const auto mesh = small_bar();
  auto damping = std::make_shared<material::RayleighDamping>(0.2, 0.005);
  fem::ElasticForce term(mesh, { model(0), nullptr, damping, 1000 });
  term.set_project_tangent(false);
  const VecX x = deformed(mesh, 0.3);
  const VecX v = random_velocity(x.size(), 3);
  VecX f;
  const Eigen::MatrixXd D = jacobian_at(term, x, v, 0.0, 1.0, f); // c_x = 0, c_v = 1: only D
  test::expect_jacobian_matches(
      -D, [&](const VecX& w) { return force_at(term, x, w); }, v, 1e-7);
  // Damping dissipates: vᵀ f_d ≤ 0.
  const VecX fd = force_at(term, x, v) - force_at(term, x, VecX::Zero(v.size()));
  EXPECT_LT(v.dot(fd), 0.0);
}

namespace {

/// A smooth isotropic correction N_i = a e_i + b e_i² + c Σ e (e = σ − 1) [Pa] with a learned
/// stiffness damping Δα₁(σ) = δ + γ (σ₀ − 1), rate-independent like the learned ones.
class QuadraticCorrection final : public material::Correction {
  public:
  QuadraticCorrection(double delta, double gamma)
      : m_delta(delta)
      , m_gamma(gamma) { }
  std::string name() const override { return "quadratic"; }
  Vec3 correction(const Vec3& s, const Vec3&) const override {
    const Vec3 e = s - Vec3::Ones();
    return (kA * e + kB * e.cwiseAbs2()).array() + kC * e.sum();
  }
  void correction_gradient(const Vec3& s, const Vec3&, Mat3& ds, Mat3& dr) const override {
    const Vec3 e = s - Vec3::Ones();
    ds = Mat3::Constant(kC);
    ds.diagonal().array() += kA + 2 * kB * e.array();
    dr.setZero();
  }
  bool depends_on_rates() const override { return false; }
  double stiffness_damping(const Vec3& s) const override { return m_delta + m_gamma * (s[0] - 1); }
  std::unique_ptr<Correction> clone() const override {
    return std::make_unique<QuadraticCorrection>(*this);
  }

  private:
  static constexpr double kA = -4e4, kB = 3e5, kC = 1e4;
  double m_delta, m_gamma;
};

} // namespace

TEST(LearnedStiffnessDamping, ForceIsAlpha1CorrectedPlusDeltaAlpha1NominalStiffnessAlongV) {
  // f_d = −α₁ K_corrected v − Δα₁ K_nominal v (paper Eq. 13; ElasticForce forms it as one
  // tangent of the weighted stresses): with a constant Δα₁, α₁ times the directional derivative
  // of the corrected elastic force plus Δα₁ times the nominal one's, by central differences
  // (O(ε²) ≈ 1e-12 relative). The corrected and nominal stiffnesses differ by ~10 % here, so a
  // Δα₁ applied to the wrong one fails by ~Δα₁/α₁ · 10 %.
  const auto mesh = small_bar();
  const double alpha1 = 0.01, delta = 0.004;
  const auto correction = std::make_shared<QuadraticCorrection>(delta, 0.0);
  const auto exact = rayleigh(0, alpha1, material::DampingTangent::Exact);
  fem::ElasticForce damped(mesh, { model(0), correction, exact, 1000 });
  fem::ElasticForce corrected(mesh, { model(0), correction, nullptr, 1000 });
  fem::ElasticForce nominal(mesh, { model(0), nullptr, nullptr, 1000 });
  const VecX x = deformed(mesh, 0.3);
  const VecX v = random_velocity(x.size(), 13);
  const VecX zero = VecX::Zero(x.size());
  const VecX f_damping = force_at(damped, x, v) - force_at(damped, x, zero);
  const double eps = 1e-6;
  const auto directional = [&](fem::ElasticForce& term) -> VecX {
    return (force_at(term, x + eps * v, zero) - force_at(term, x - eps * v, zero)) / (2 * eps);
  };
  const VecX d_corrected = directional(corrected), d_nominal = directional(nominal);
  ASSERT_GT((d_corrected - d_nominal).norm(), 0.05 * d_nominal.norm());
  EXPECT_LE(
      (f_damping - (alpha1 * d_corrected + delta * d_nominal)).norm(), 1e-6 * f_damping.norm());
}

TEST(LearnedStiffnessDamping, UnprojectedJacobianIsMinusTheVelocityDerivative) {
  // With Δα₁ varying per element (and α₁ + Δα₁ clamped at 0 in some), the damping force is still
  // linear in v: Newton's c_v block must be exactly −∂f/∂v (central differences, exact for a
  // linear function up to round-off).
  const auto mesh = small_bar();
  for (const double alpha1 : { 0.01, 0.0 }) {
    SCOPED_TRACE(testing::Message() << "alpha1 " << alpha1);
    const auto correction = std::make_shared<QuadraticCorrection>(0.003, 0.05);
    fem::ElasticForce term(mesh,
        { model(0), correction, rayleigh(0.2, alpha1, material::DampingTangent::FlipFree), 1000 });
    term.set_project_tangent(false);
    const VecX x = deformed(mesh, 0.3);
    const VecX v = random_velocity(x.size(), 17);
    VecX f;
    test::expect_jacobian_matches(
        -jacobian_at(term, x, v, 0.0, 1.0, f), [&](const VecX& w) { return force_at(term, x, w); },
        v, 1e-7);
  }
}

TEST(LearnedStiffnessDamping, TheFlipFreeDampingDissipatesWhereTheCorrectedStiffnessIsNot) {
  // Δα₁ = −α₁ removes the nominal's stiffness damping, leaving α₁ K^d(N): the correction's
  // stiffness alone, indefinite (−4e4 Pa on its diagonal near rest). Taken as it is (the exact
  // tangent, standard Rayleigh damping) that damping force does positive work for some velocities;
  // the flip-free one, taken at its dissipative part, does none for any.
  const auto mesh = small_bar();
  const double alpha1 = 0.01;
  const auto correction = std::make_shared<QuadraticCorrection>(-alpha1, 0.0);
  const VecX x = deformed(mesh, 0.1);
  const VecX zero = VecX::Zero(x.size());
  const auto largest_power = [&](material::DampingTangent kind) {
    fem::ElasticForce term(mesh, { model(0), correction, rayleigh(0, alpha1, kind), 1000 });
    const VecX f0 = force_at(term, x, zero);
    double largest = -std::numeric_limits<double>::infinity();
    for (unsigned seed = 1; seed <= 20; ++seed) {
      const VecX v = random_velocity(x.size(), seed);
      const VecX damping = force_at(term, x, v) - f0;
      largest = std::max(largest, v.dot(damping) / (v.norm() * f0.norm()));
    }
    return largest;
  };
  // Relative to |v| |f(x, 0)|; round-off of the difference is ~1e-16 of it.
  EXPECT_GT(largest_power(material::DampingTangent::Exact), 1e-4);
  EXPECT_LE(largest_power(material::DampingTangent::FlipFree), 1e-12);
}

namespace {

/// Per-element stiffness scales spread log-uniformly over [1e-2, 1e2], deterministic.
std::shared_ptr<const std::vector<double>> random_scales(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> exponent(-2, 2);
  auto scales = std::make_shared<std::vector<double>>(count);
  for (double& s : *scales)
    s = std::pow(10.0, exponent(rng));
  return scales;
}

} // namespace

TEST(StiffnessScale, ScaledStiffnessIsMinusForceDerivativeAndEnergyGradient) {
  // Heterogeneous material: element e's stress is s_e P̂ with s_e over four decades. The exact
  // stiffness must still be −∂f/∂x and the force −∂E/∂x (central differences, as the
  // homogeneous test); the scales must matter (the forces differ from the unscaled ones).
  const auto mesh = small_bar();
  fem::MaterialModel scaled { model(0), nullptr, nullptr, 1000 };
  scaled.stiffness_scale = random_scales(mesh.num_tets(), 3);
  fem::ElasticForce term(mesh, scaled);
  fem::ElasticForce plain(mesh, { model(0), nullptr, nullptr, 1000 });
  term.set_project_tangent(false);
  const VecX x = deformed(mesh, 0.4);
  const VecX v = VecX::Zero(x.size());
  VecX f;
  const Eigen::MatrixXd K = jacobian_at(term, x, v, 1.0, 0.0, f);
  ASSERT_GT((f - force_at(plain, x, v)).norm(), 0.5 * f.norm());
  expect_consistent_stiffness_and_energy(term, x, v, K, f);
}

TEST(StiffnessScale, RayleighDampingScalesTheScaledStiffness) {
  // f_d = −α₁ K(x) v with K the heterogeneous material's exact stiffness: α₁ times the
  // directional derivative of the scaled elastic force (central differences, O(ε²)).
  const auto mesh = small_bar();
  const double alpha1 = 0.01;
  const auto scales = random_scales(mesh.num_tets(), 5);
  fem::MaterialModel damped_model { model(2), nullptr,
    rayleigh(0, alpha1, material::DampingTangent::Exact), 1000 };
  damped_model.stiffness_scale = scales;
  fem::MaterialModel elastic_model { model(2), nullptr, nullptr, 1000 };
  elastic_model.stiffness_scale = scales;
  fem::ElasticForce damped(mesh, damped_model), elastic(mesh, elastic_model);
  const VecX x = deformed(mesh, 0.3);
  const VecX v = random_velocity(x.size(), 11);
  const VecX zero = VecX::Zero(x.size());
  const VecX f_damping = force_at(damped, x, v) - force_at(damped, x, zero);
  const double eps = 1e-6;
  const VecX directional
      = (force_at(elastic, x + eps * v, zero) - force_at(elastic, x - eps * v, zero)) / (2 * eps);
  EXPECT_LE((f_damping - alpha1 * directional).norm(), 1e-6 * f_damping.norm());
}

TEST(StiffnessScale, UniformScaleIsAStifferNominalAndLeavesTheCorrectionUnscaled) {
  // Every model's stress is linear in (μ, λ): a uniform scale s is the material with s·E (same
  // ν). With a correction N and a learned Δα₁, s P̂ + N must equal that stiffer nominal plus the
  // same N (a scaled N would differ by (s − 1) N, ~10 % of the force here), and the damping
  // (α₁ on the corrected stiffness, Δα₁ on the nominal one) and the Jacobians must agree too.
  // Same arithmetic up to the order of operations: 1e-12 relative.
  const auto mesh = small_bar();
  const double s = 7;
  const auto correction = std::make_shared<QuadraticCorrection>(0.004, 0.02);
  const auto damping = rayleigh(0.3, 0.01, material::DampingTangent::Exact);
  fem::MaterialModel scaled { model(0), correction, damping, 1000 };
  scaled.stiffness_scale = std::make_shared<std::vector<double>>(mesh.num_tets(), s);
  const auto stiffer = std::make_shared<material::CorotatedModel>(
      material::Lame::from_young_poisson(3e5 * s, 0.4));
  fem::ElasticForce a(mesh, scaled), b(mesh, { stiffer, correction, damping, 1000 });
  fem::ElasticForce without(mesh, { stiffer, nullptr, damping, 1000 });
  const VecX x = deformed(mesh, 0.3);
  const VecX v = random_velocity(x.size(), 19);
  VecX fa, fb;
  const Eigen::MatrixXd Ja = jacobian_at(a, x, v, 1.0, 0.05, fa);
  const Eigen::MatrixXd Jb = jacobian_at(b, x, v, 1.0, 0.05, fb);
  ASSERT_GT((fb - force_at(without, x, v)).norm(), 1e-3 * fb.norm());
  EXPECT_LE((fa - fb).norm(), 1e-12 * fb.norm());
  EXPECT_LE((Ja - Jb).norm(), 1e-12 * Jb.norm());
  EXPECT_NEAR(a.elastic_energy(x), b.elastic_energy(x), 1e-12 * b.elastic_energy(x));
}

TEST(LearnedEnergy, TheEnergyOfAnEnergyCorrectionIsPartOfTheElasticEnergy) {
  // Energy kernels and linear tails (a softening kernel, a Lamé change), on a stiffness-scaled
  // nominal: −∇E = f at v = 0 by central differences (1e-6 relative, as for the nominals), and the
  // correction's share is ~10 % of the force, so an energy without ΔΨ fails by far.
  const auto mesh = small_bar();
  material::RbfCorrection::Parameters p;
  p.energy_kernels = true;
  p.epsilon = 0.1;
  p.centres = Eigen::RowVector3d(1.05, 1.0, 0.97);
  p.weights = VecX::Constant(1, -2e3);
  p.own_slope = 3e4;
  p.other_slope = 1e4;
  const auto correction = std::make_shared<material::RbfCorrection>(std::move(p));
  ASSERT_TRUE(correction->has_elastic_energy());
  fem::MaterialModel m { model(0), correction, nullptr, 1000 };
  m.stiffness_scale = std::make_shared<std::vector<double>>(mesh.num_tets(), 1.3);
  fem::ElasticForce term(mesh, m);
  term.set_project_tangent(false);
  fem::MaterialModel plain = m;
  plain.correction = nullptr;
  fem::ElasticForce nominal(mesh, plain);
  const VecX x = deformed(mesh, 0.3);
  const VecX v = VecX::Zero(x.size());
  VecX f;
  const Eigen::MatrixXd K = jacobian_at(term, x, v, 1.0, 0.0, f);
  ASSERT_GT((f - force_at(nominal, x, v)).norm(), 0.03 * f.norm());
  expect_consistent_stiffness_and_energy(term, x, v, K, f);
  // A correction without an energy leaves the nominal's.
  fem::MaterialModel stress = m;
  stress.correction = std::make_shared<QuadraticCorrection>(0.004, 0.0);
  EXPECT_EQ(fem::ElasticForce(mesh, stress).elastic_energy(x), nominal.elastic_energy(x));
}

TEST(StiffnessScale, RejectsAScaleOfTheWrongSize) {
  const auto mesh = small_bar();
  fem::MaterialModel m { model(0), nullptr, nullptr, 1000 };
  m.stiffness_scale = std::make_shared<std::vector<double>>(mesh.num_tets() - 1, 1.0);
  EXPECT_ANY_THROW(fem::ElasticForce(mesh, m));
}
