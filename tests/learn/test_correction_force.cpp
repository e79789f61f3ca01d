// The correction's nodal force (learn::correction_force) is fem::ElasticForce's force with the
// correction minus without it, on a small randomly deformed and moving mesh with Rayleigh damping
// (both damping tangents), a Δα₁ clamped at α₁ + Δα₁ ≥ 0 in some elements, a per-element
// stiffness scale and a rate-dependent or a learned (RBF) correction; and CorrectionForceJacobian
// applied to an RBF design's unknowns is that force.
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/learn/correction_force.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/element_stress.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/rbf_correction.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <support/damped_analytic_correction.hpp>

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <random>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

constexpr double kAlpha1 = 0.02; ///< the nominal Rayleigh α₁ [s]

mesh::TetMesh small_mesh() {
  return mesh::make_box_bar(Vec3(0.3, 0.1, 0.1), { 3, 2, 2 }); // 72 tets
}

/// N = AnalyticCorrection (a cubic in the stretches plus a stretch-rate viscous term, so N
/// depends on the rates) and Δα₁(σ) = δ + γ (σ₀ − 1).
test::DampedAnalyticCorrection viscous_correction(double delta, double gamma) {
  return { { 1e5, 200.0, 3.0 }, delta, gamma };
}

/// A learned-type correction: 5 stress kernels near rest with a tail, and a damping part that
/// keeps α₁ + Δα₁ > 0 at the test's states (its damping then dissipates: checked where used).
material::RbfCorrection rbf_correction() {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  material::RbfCorrection::Parameters p;
  p.centres.resize(5, 3);
  p.weights.resize(5);
  p.damping_weights.resize(5);
  for (int i = 0; i < 5; ++i) {
    p.centres.row(i) = Eigen::RowVector3d(1 + 0.1 * u(rng), 1 + 0.1 * u(rng), 1 + 0.1 * u(rng));
    p.weights[i] = 3e3 * u(rng);
    p.damping_weights[i] = 0.01 * u(rng);
  }
  p.own_slope = -5e3;
  p.other_slope = 2e3;
  p.damping_constant = 0.01;
  p.damping_slopes = Vec3(-0.03, 0, 0);
  return material::RbfCorrection(p);
}

/// x = R (X + A X + jitter) + c with |A_ij| ≤ 0.15 and a vertex jitter of 8 % of a cell, v of
/// 0.1 m/s per component: stretches within about [0.75, 1.3], no inversion.
struct State {
  VecX x, v;
};
State random_state(const mesh::TetMesh& mesh, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  Mat3 A;
  for (int k = 0; k < 9; ++k)
    A.data()[k] = 0.15 * u(rng);
  const Mat3 R = Eigen::Quaterniond(1.0, 0.3, -0.2, 0.1).normalized().toRotationMatrix();
  const Positions& X = mesh.rest_positions();
  State s { VecX(3 * X.rows()), VecX(3 * X.rows()) };
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    const Vec3 p = X.row(i).transpose();
    const Vec3 jitter(0.004 * u(rng), 0.004 * u(rng), 0.004 * u(rng));
    s.x.segment<3>(3 * i) = R * (p + A * p + jitter) + Vec3(0.1, -0.2, 0.05);
    s.v.segment<3>(3 * i) = 0.1 * Vec3(n(rng), n(rng), n(rng));
  }
  return s;
}

/// Log-uniform per-tet stiffness scales in [0.5, 2].
std::shared_ptr<const std::vector<double>> random_scales(int tets) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(std::log(0.5), std::log(2.0));
  auto scales = std::make_shared<std::vector<double>>(tets);
  for (double& s : *scales)
    s = std::exp(u(rng));
  return scales;
}

fem::MaterialModel nominal(material::DampingTangent kind,
    std::shared_ptr<const std::vector<double>> scales, double alpha1 = kAlpha1) {
  auto damping = std::make_shared<material::RayleighDamping>(0.3, alpha1);
  damping->set_tangent(kind);
  return { std::make_shared<material::CorotatedModel>(material::Lame::from_young_poisson(5e4, 0.4)),
    nullptr, damping, 1000, std::move(scales) };
}

/// fem::ElasticForce's force with `correction` minus without it.
VecX elastic_force_difference(const mesh::TetMesh& mesh, fem::MaterialModel material,
    const material::Correction& correction, const State& s) {
  fem::ElasticForce without(mesh, material);
  material.correction = correction.clone();
  fem::ElasticForce with(mesh, material);
  VecX f = VecX::Zero(s.x.size()), f0 = VecX::Zero(s.x.size());
  with.add_force({ s.x, s.v }, f);
  without.add_force({ s.x, s.v }, f0);
  return f - f0;
}

/// How many elements have α₁ + Δα₁ < 0 (clamped) at `s`.
int clamped_elements(
    const ReconstructionMesh& mesh, const material::Correction& correction, const State& s) {
  std::vector<ElementState> states;
  compute_element_states(mesh, s.x, s.v, states);
  int count = 0;
  for (const ElementState& e : states)
    count += kAlpha1 + correction.stiffness_damping(e.frame.stretches) < 0;
  return count;
}

/// How many elements' stiffness-damping tangent (material::ElementStress::damped, of `kind`) does
/// not dissipate at `s`: a negative eigenvalue of its block's symmetric part or a negative twist
/// or flip. fem::ElasticForce takes the flip-free one at its dissipative part there, where the
/// learning's correction force, linear in the correction, does not.
int non_dissipative_elements(const ReconstructionMesh& mesh, const fem::MaterialModel& material,
    const material::Correction& correction, const State& s, material::DampingTangent kind) {
  std::vector<ElementState> states;
  compute_element_states(mesh, s.x, s.v, states);
  const material::ElementMaterial element { material.elastic.get(), &correction,
    material.damping.get(), 1.0 };
  int count = 0;
  for (size_t e = 0; e < states.size(); ++e) {
    material::ElementMaterial scaled = element;
    if (material.stiffness_scale)
      scaled.stiffness_scale = (*material.stiffness_scale)[e];
    const material::PrincipalFrame& frame = states[e].frame;
    const material::ElementStress stress
        = material::element_stress(scaled, frame.stretches, states[e].stretch_rates);
    const material::PrincipalTangent t = material::damping_tangent(frame, stress.damped(), kind);
    const Mat3 symmetric = 0.5 * (t.block + t.block.transpose());
    count += Eigen::SelfAdjointEigenSolver<Mat3>(symmetric).eigenvalues().minCoeff() < 0
        || t.twist.minCoeff() < 0 || t.flip.minCoeff() < 0;
  }
  return count;
}

} // namespace

TEST(CorrectionForce, IsTheElasticForceWithTheCorrectionMinusWithout) {
  const mesh::TetMesh mesh = small_mesh();
  const int m = mesh.num_tets();
  const auto scales = random_scales(m);
  const auto viscous = viscous_correction(-0.01, -0.1);
  const material::RbfCorrection rbf = rbf_correction();
  const State s = random_state(mesh, 3);
  const State still { s.x, VecX::Zero(s.v.size()) };
  for (const material::DampingTangent kind : material::all_damping_tangents)
    for (const material::Correction* correction :
        std::initializer_list<const material::Correction*> { &viscous, &rbf }) {
      SCOPED_TRACE(
          testing::Message() << material::to_string(kind) << ", correction " << correction->name());
      const ReconstructionMesh geometry(mesh, nominal(kind, scales));
      // The identity holds where ElasticForce's flip-free damping is its unprojected tangent: at
      // every element here (with the exact tangent, unprojected by design, at none).
      const int non_dissipative
          = non_dissipative_elements(geometry, nominal(kind, scales), *correction, s, kind);
      if (kind == material::DampingTangent::FlipFree)
        ASSERT_EQ(non_dissipative, 0);
      else
        EXPECT_GT(non_dissipative, 0);
      const VecX f = correction_force(geometry, *correction, s.x, s.v);
      const VecX expected = elastic_force_difference(mesh, nominal(kind, scales), *correction, s);
      // The same kernel arithmetic, the nominal parts cancelling in ElasticForce's difference:
      // agreement to round-off of the total force (measured 8e-16 relative); a Δα₁ on the wrong
      // stiffness, a missed scale or clamp is off by > 1e-3 (below).
      EXPECT_LE(
          (f - expected).lpNorm<Eigen::Infinity>(), 1e-10 * expected.lpNorm<Eigen::Infinity>());
      // Every part is exercised: the damping (f with v minus f at rest: measured 96–99 % of f)
      // and the stiffness scale (Δα₁ damps s_e P̂: ignoring s_e changes f by 19–24 %).
      const VecX at_rest = correction_force(geometry, *correction, still.x, still.v);
      EXPECT_GT((f - at_rest).norm(), 0.05 * f.norm());
      const VecX unscaled = correction_force(
          ReconstructionMesh(mesh, nominal(kind, nullptr)), *correction, s.x, s.v);
      EXPECT_GT((f - unscaled).norm(), 1e-3 * f.norm());
    }
  // The clamp α₁ + Δα₁ ≥ 0 binds in some elements of the viscous correction, not in all.
  const int clamped = clamped_elements(ReconstructionMesh(mesh), viscous, s);
  EXPECT_GT(clamped, 0);
  EXPECT_LT(clamped, m);
}

TEST(CorrectionForce, AMassDampingChangeDampsTheLumpedMassAsTheSimulatorDoes) {
  // Δα₀ adds −Δα₀ (ρ V_e / 4) v_a per element, kept α₀ + Δα₀ ≥ 0 (the nominal's α₀ is 0.3):
  // with a Δα₀ that leaves α₀ positive and with one that the clamp cuts to −α₀.
  const mesh::TetMesh mesh = small_mesh();
  const State s = random_state(mesh, 6);
  const auto scales = random_scales(mesh.num_tets());
  const material::RbfCorrection plain = rbf_correction();
  const fem::MaterialModel material = nominal(material::DampingTangent::FlipFree, scales);
  const ReconstructionMesh geometry(mesh, material);
  const VecX f_plain = correction_force(geometry, plain, s.x, s.v);
  for (const double change : { 0.2, -0.1, -0.5 }) {
    SCOPED_TRACE(change);
    auto p = plain.parameters();
    p.mass_damping = change;
    const material::RbfCorrection damped(p);
    const VecX f = correction_force(geometry, damped, s.x, s.v);
    const VecX expected = elastic_force_difference(mesh, material, damped, s);
    EXPECT_LE((f - expected).lpNorm<Eigen::Infinity>(), 1e-10 * expected.lpNorm<Eigen::Infinity>());
    // The mass term itself: the applied change times −M v (lumped), M from ρ = 1000.
    const double applied = std::max(change, -0.3);
    VecX mass_force = VecX::Zero(s.x.size());
    for (int e = 0; e < mesh.num_tets(); ++e)
      for (int a = 0; a < 4; ++a) {
        const int i = mesh.tets()(e, a);
        mass_force.segment<3>(3 * i)
            -= applied * 1000 * geometry.rest[e].volume / 4 * s.v.segment<3>(3 * i);
      }
    EXPECT_LE(
        (f - f_plain - mass_force).lpNorm<Eigen::Infinity>(), 1e-10 * f.lpNorm<Eigen::Infinity>());
    // Small next to the elastic force (ρ = 1000, v ~ 0.1 m/s: measured 3e-5–1e-4 of it), but far
    // above the tolerances above, so a wrong mass, sign or clamp fails them.
    EXPECT_GT(mass_force.lpNorm<Eigen::Infinity>(), 1e-6 * f.lpNorm<Eigen::Infinity>());
  }
}

TEST(CorrectionForce, WithoutANominalElasticModelIsTheCorrectionStressAlone) {
  // No nominal model: B N(σ, ḟ) only (no damping, no Δα₁), i.e. ElasticForce's difference with
  // the nominal and the Rayleigh damping switched off.
  const mesh::TetMesh mesh = small_mesh();
  const auto viscous = viscous_correction(0.01, 0.0);
  const State s = random_state(mesh, 4);
  fem::MaterialModel undamped = nominal(material::DampingTangent::FlipFree, nullptr);
  undamped.damping = nullptr;
  const auto no_delta = viscous_correction(0.0, 0.0);
  const VecX expected = elastic_force_difference(mesh, undamped, no_delta, s);
  const VecX f = correction_force(ReconstructionMesh(mesh), viscous, s.x, s.v);
  EXPECT_LE((f - expected).lpNorm<Eigen::Infinity>(), 1e-10 * expected.lpNorm<Eigen::Infinity>());
  EXPECT_GT(expected.norm(), 0.0);
}

TEST(CorrectionForceJacobian, TimesTheUnknownsIsTheCorrectionForce) {
  // J x = correction_force of the design's correction with unknowns x (restricted to the free
  // dofs), with damping, Δα₁ (clamp inactive: checked) and a stiffness scale.
  const mesh::TetMesh mesh = small_mesh();
  std::vector<int> fixed;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.rest_positions()(i, 0) == 0.0)
      fixed.push_back(i);
  const fem::DofMap dofs(mesh.num_vertices(), fixed);
  const State s = random_state(mesh, 5);
  const auto scales = random_scales(mesh.num_tets());
  for (const bool mass_damping : { false, true })
    for (const material::DampingTangent kind : material::all_damping_tangents) {
      SCOPED_TRACE(testing::Message() << material::to_string(kind) << ", Δα₀ " << mass_damping);
      RbfFitOptions options;
      options.mass_damping = mass_damping; // its column −M v, with Δα₀ within the clamp
      const RbfDesign design(rbf_correction().parameters().centres, options);
      ASSERT_GT(design.damping_unknowns(), 0);
      std::mt19937 rng(8);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      VecX unknowns(design.num_unknowns());
      for (int i = 0; i < unknowns.size(); ++i)
        unknowns[i] = (i < design.elastic_unknowns() ? 2e3 : 1e-3) * u(rng);
      if (mass_damping)
        unknowns[design.mass_damping_unknown()] = 0.15;
      const material::RbfCorrection correction = design.correction(unknowns);
      const ReconstructionMesh geometry(mesh, nominal(kind, scales));
      ASSERT_EQ(clamped_elements(geometry, correction, s), 0);
      CorrectionForceJacobian jacobian(geometry, dofs, design);
      const VecX Jx = jacobian.transposed(s.x, s.v).transpose() * unknowns;
      const VecX f = dofs.restrict(correction_force(geometry, correction, s.x, s.v));
      // Linear in the unknowns up to round-off of the operator columns (measured 1e-15).
      EXPECT_LE((Jx - f).lpNorm<Eigen::Infinity>(), 1e-9 * f.lpNorm<Eigen::Infinity>());
      EXPECT_GT(f.norm(), 0.0);
    }
}

TEST(CorrectionForceJacobian, FramesFromAnElasticForceAtTheStateGiveTheSameJacobian) {
  // The forward fit hands J the principal frames its residual's force pass computed at x: J must
  // be bit for bit the one from its own SVDs, and frames cached at another state are refused.
  const mesh::TetMesh mesh = small_mesh();
  const fem::DofMap dofs(mesh.num_vertices(), {});
  const State s = random_state(mesh, 5), other = random_state(mesh, 6);
  const RbfDesign design(rbf_correction().parameters().centres, RbfFitOptions {});
  const ReconstructionMesh geometry(mesh, nominal(material::DampingTangent::FlipFree, nullptr));
  fem::ElasticForce force(mesh, geometry.nominal);
  VecX f = VecX::Zero(s.x.size());
  force.add_force({ s.x, other.v }, f); // the frames depend on x only
  ASSERT_TRUE(force.caches_positions(s.x));
  CorrectionForceJacobian own(geometry, dofs, design), shared(geometry, dofs, design);
  const MatX expected = own.transposed(s.x, s.v);
  EXPECT_EQ(shared.transposed(s.x, s.v, force), expected);
  EXPECT_GT(expected.norm(), 0.0);
  EXPECT_FALSE(force.caches_positions(other.x));
  EXPECT_THROW(shared.transposed(other.x, other.v, force), std::logic_error);
}
