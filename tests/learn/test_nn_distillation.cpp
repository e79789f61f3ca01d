// Network correction training and distillation (paper 000 §6.2): batch-norm folding is exact,
// training reaches a small error on a known smooth correction, runs are deterministic, and the
// simulation sampler records what the teacher sees.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/nn_distillation.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <support/bar_scene.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <random>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// A teacher like the learning loop's: the isotropic linear tail of nominal Lamé parameters off
/// by Δμ = 3 kPa, Δλ = 4 kPa (a = 2Δμ + Δλ, b = Δλ), 4 centres around rest with elastic weights
/// ~1e3 Pa (over the sampled box the linear and kernel stresses are both ~1e3 Pa), and a damping
/// RBF Δα₁ ~ 1e-3 s with Δα₀ 0.3 /s, which distillation carries over instead of fitting.
material::RbfCorrection smooth_teacher() {
  material::RbfCorrection::Parameters p;
  p.centres.resize(4, 3);
  p.centres << 1.0, 1.0, 1.0, 1.15, 1.0, 0.9, 1.05, 0.95, 0.85, 0.95, 0.92, 0.9;
  p.weights = Eigen::Vector4d(800, -500, 300, -400);
  p.own_slope = 2 * 3e3 + 4e3;
  p.other_slope = 4e3;
  p.damping_weights = Eigen::Vector4d(4e-3, -2e-3, 3e-3, -1e-3);
  p.damping_constant = 1e-3;
  p.mass_damping = 0.3;
  p.epsilon = 0.05;
  return material::RbfCorrection(std::move(p));
}

/// n samples with stretches uniform in [0.85, 1.15]³ and rates N(0, 1/s²), targets from `teacher`.
StressSamples random_samples(const material::Correction& teacher, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.85, 1.15);
  std::normal_distribution<double> g(0.0, 1.0);
  StressSamples s;
  s.stretches.resize(n, 3);
  s.stretch_rates.resize(n, 3);
  s.targets.resize(n, 3);
  for (int j = 0; j < n; ++j) {
    const Vec3 sigma(u(rng), u(rng), u(rng)), rate(g(rng), g(rng), g(rng));
    s.stretches.row(j) = sigma.transpose();
    s.stretch_rates.row(j) = rate.transpose();
    // As distillation_samples: the elastic correction only (Δα₁ is carried over, not distilled).
    s.targets.row(j) = teacher.correction(sigma, rate).transpose();
  }
  return s;
}

/// NnCorrection with identity standardisation around the given layers.
material::NnCorrection identity_wrapped(std::vector<material::NnCorrection::Layer> layers) {
  material::NnCorrection::Parameters p;
  p.layers = std::move(layers);
  return material::NnCorrection(std::move(p));
}

/// Random network inputs (6 × n), standard normal.
MatX random_inputs(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  MatX x(6, n);
  for (Eigen::Index i = 0; i < x.size(); ++i)
    x.data()[i] = g(rng);
  return x;
}

/// max over the columns of |g(x_j) − reference_j|, g the folded network, relative to the RMS
/// of the reference (a single output near 0 would make a per-sample ratio meaningless).
double max_relative_difference(
    const material::NnCorrection& folded, const MatX& x, const MatX& reference) {
  double worst = 0;
  for (Eigen::Index j = 0; j < x.cols(); ++j)
    worst = std::max(worst, std::abs(folded.evaluate(x.col(j)) - reference(0, j)));
  return worst / (reference.norm() / std::sqrt(double(reference.size())));
}

} // namespace

TEST(BatchNormFolding, FoldedNetworkEqualsTheInferenceModeNetwork) {
  // Random γ, β, biases and running statistics (variances 0.1–2.1), so every term of the fold
  // W' = diag(s) W, b' = s ⊙ (b − μ) + β matters. Same arithmetic up to reassociation:
  // agreement to round-off (1e-12 relative of outputs ~1).
  BatchNormMlp net = make_batch_norm_mlp(6, { 6, 6 }, 1, true, 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (auto& l : net.layers) {
    l.bias = l.bias.unaryExpr([&](double) { return u(rng); });
    if (!l.has_batch_norm())
      continue;
    l.gamma = l.gamma.unaryExpr([&](double) { return 1.5 * u(rng); });
    l.beta = l.beta.unaryExpr([&](double) { return u(rng); });
    l.running_mean = l.running_mean.unaryExpr([&](double) { return u(rng); });
    l.running_var = l.running_var.unaryExpr([&](double) { return 1.1 + u(rng); });
  }
  const MatX x = random_inputs(200, 4);
  const MatX inference = evaluate(net, x, BatchNormMode::Inference);
  const auto folded = identity_wrapped(fold_batch_norm(net));
  EXPECT_LT(max_relative_difference(folded, x, inference), 1e-12);
  // The fold really uses the running statistics: training mode (batch statistics) differs.
  EXPECT_GT(
      (evaluate(net, x, BatchNormMode::Training) - inference).norm(), 1e-3 * inference.norm());
}

TEST(BatchNormFolding, TrainingModeEqualsFoldedWhenRunningStatisticsAreTheBatchStatistics) {
  // Set each layer's running mean/variance to the statistics its batch-norm sees on one batch
  // (layer by layer, in training mode): then the training-mode outputs on that batch are what
  // the folded network computes sample by sample. Round-off only: 1e-12.
  BatchNormMlp net = make_batch_norm_mlp(6, { 6, 6 }, 1, true, 8);
  const MatX x = random_inputs(64, 9);
  MatX a = x;
  for (std::size_t k = 0; k + 1 < net.layers.size(); ++k) {
    auto& l = net.layers[k];
    l.gamma.setConstant(0.7);
    l.beta.setConstant(0.2);
    MatX z = l.weight * a;
    z.colwise() += l.bias;
    l.running_mean = z.rowwise().mean();
    l.running_var = (z.colwise() - l.running_mean).rowwise().squaredNorm() / double(z.cols());
    BatchNormMlp prefix;
    prefix.layers.assign(net.layers.begin(), net.layers.begin() + static_cast<long>(k) + 1);
    prefix.layers.emplace_back(); // evaluate() needs a last (linear) layer: identity
    prefix.layers.back().weight = MatX::Identity(l.weight.rows(), l.weight.rows());
    prefix.layers.back().bias = VecX::Zero(l.weight.rows());
    a = evaluate(prefix, x, BatchNormMode::Training);
  }
  const MatX training = evaluate(net, x, BatchNormMode::Training);
  const auto folded = identity_wrapped(fold_batch_norm(net));
  EXPECT_LT(max_relative_difference(folded, x, training), 1e-12);
}

TEST(NnDistillation, LearnsASmoothCorrection) {
  // 12 000 samples (36 000 direction rows) of the RBF teacher. The shared 6 → 6 → 6 → 1 network
  // reaches a validation RMS of 1.7 % of the target RMS (docs/learning.md); the bound
  // 5 % leaves room for platform round-off changing the optimisation path. A 1-epoch network
  // is far above it, so the bound tests the training, not the architecture alone.
  const auto teacher = smooth_teacher();
  const StressSamples samples = random_samples(teacher, 12000, 21);
  NnDistillationOptions o;
  const NnDistillationResult r = distill_nn_correction(samples, o);
  RecordProperty("relative_validation_rms", std::to_string(r.relative_validation_rms()));
  std::cout << "epochs " << r.training.epochs << " (best " << r.training.best_epoch << "), "
            << r.training.seconds << " s, relative RMS train " << r.relative_training_rms()
            << " validation " << r.relative_validation_rms() << "\n";
  EXPECT_EQ(r.training_samples + r.validation_samples, 12000);
  EXPECT_LT(r.relative_validation_rms(), 0.05);
  EXPECT_LT(r.relative_training_rms(), 0.05);

  NnDistillationOptions short_run = o;
  short_run.training.max_epochs = 1;
  EXPECT_GT(distill_nn_correction(samples, short_run).relative_validation_rms(),
      2 * r.relative_validation_rms());
}

TEST(NnDistillation, DeterministicForASeed) {
  const auto teacher = smooth_teacher();
  const StressSamples samples = random_samples(teacher, 2000, 5);
  NnDistillationOptions o;
  o.training.max_epochs = 15;
  const auto a = distill_nn_correction(samples, o);
  const auto b = distill_nn_correction(samples, o);
  const auto& pa = a.correction.parameters();
  const auto& pb = b.correction.parameters();
  ASSERT_EQ(pa.layers.size(), pb.layers.size());
  for (std::size_t k = 0; k < pa.layers.size(); ++k) {
    EXPECT_EQ(pa.layers[k].weight, pb.layers[k].weight);
    EXPECT_EQ(pa.layers[k].bias, pb.layers[k].bias);
  }
  EXPECT_EQ(a.validation_rms, b.validation_rms);
  o.training.seed = 2;
  const auto c = distill_nn_correction(samples, o);
  EXPECT_NE(pa.layers[0].weight, c.correction.parameters().layers[0].weight);
}

TEST(NnDistillation, DistilledNetworkIsIsotropic) {
  // Whatever the fitting error, the distilled network gives exactly equal outputs to directions
  // with equal stretches and rates (the same network on the same view), and the world-frame
  // stress at a repeated stretch does not depend on the SVD's choice of U, V there.
  const auto teacher = smooth_teacher();
  NnDistillationOptions o;
  o.training.max_epochs = 15;
  const auto r = distill_nn_correction(random_samples(teacher, 2000, 5), o);
  const material::NnCorrection& n = r.correction;
  for (const Vec3& s : { Vec3::Ones().eval(), Vec3(1.1, 1.1, 0.9), Vec3(0.9, 1.05, 0.9) }) {
    for (const Vec3& f :
        { Vec3::Zero().eval(), Vec3(0.5, 0.5, 0.5), Vec3(0.3, 0.3, -0.4), Vec3(0.3, -0.4, 0.3) }) {
      const Vec3 out = n.correction(s, f);
      for (int i = 0; i < 3; ++i) {
        for (int j = i + 1; j < 3; ++j) {
          if (s[i] == s[j] && f[i] == f[j]) {
            EXPECT_EQ(out[i], out[j]) << s.transpose() << " / " << f.transpose();
          }
        }
      }
    }
  }
  // F = R diag(1.1, 1, 1) Qᵀ at zero rate: turning U, V together about their first column
  // (the degenerate plane) leaves P = U diag(N) Vᵀ unchanged up to round-off (1e-12 of |N|).
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mat3 Q = Eigen::AngleAxisd(-0.4, Vec3(-2, 1, 1).normalized()).toRotationMatrix();
  const material::PrincipalFrame frame
      = material::principal_frame(R * Vec3(1.1, 1, 1).asDiagonal() * Q.transpose());
  const Vec3 out = n.correction(frame.stretches, Vec3::Zero());
  material::PrincipalFrame turned = frame;
  const Mat3 G = Eigen::AngleAxisd(1.2, Vec3::UnitX()).toRotationMatrix();
  turned.U = frame.U * G;
  turned.V = frame.V * G;
  EXPECT_LT((material::first_piola(turned, out) - material::first_piola(frame, out)).norm(),
      1e-12 * out.norm());
}

TEST(NnDistillation, RejectsBadInput) {
  NnDistillationOptions o;
  StressSamples s = random_samples(smooth_teacher(), 100, 1);
  s.targets(3, 1) = std::nan("");
  EXPECT_THROW(distill_nn_correction(s, o), InputError);
  s = random_samples(smooth_teacher(), 3, 1); // too few for two splits of ≥ 2
  EXPECT_THROW(distill_nn_correction(s, o), InputError);
  o.validation_fraction = 1.0;
  EXPECT_THROW(o.validate(), InputError);
  o = {};
  o.training.hidden_widths = { 6, 33 };
  EXPECT_THROW(o.validate(), InputError);
}

namespace {

/// A clamped bar (8 × 2 × 2 cells, 192 tets) swinging from an initial velocity, corotated nominal.
sim::Scene swinging_bar() {
  sim::Scene s
      = test::bar_scene({ .young = 5e4, .gravity = Vec3::Zero(), .dt = 5e-3, .frames = 30 });
  s.name = "bar";
  s.initial.kind = sim::InitialCondition::Kind::Velocity;
  s.initial.velocity = Vec3(0, 0.5, 0);
  return s;
}

} // namespace

TEST(DistillationSamples, RecordsTheTeachersStatesFromSimulations) {
  const material::AnalyticCorrection teacher({ 2e5, 50, 10 });
  const sim::Scene bar = swinging_bar();
  const std::vector<double> factors { 1.0, 2.0 };
  const auto scenes = scaled_motions(bar, factors);
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_EQ(scenes[1].initial.velocity, Vec3(0, 1.0, 0));
  sim::Scene drooping = bar;
  drooping.gravity = Vec3(0, -9.81, 0);
  EXPECT_EQ(scaled_motions(drooping, factors)[1].gravity,
      Vec3(0, -2 * 9.81, 0)); // gravity-driven motions scale too
  EXPECT_EQ(scenes[1].name, "bar_x2");

  DistillationSampleOptions o;
  o.recorded_samples = 3000;
  o.frame_stride = 2;
  o.jitter_copies = 2;
  DistillationSampleReport report;
  const StressSamples s
      = distillation_samples(std::span<const sim::Scene>(scenes), teacher, o, &report);
  // 2 scenes × 16 recorded frames (0, 2, …, 30) × 192 tets = 6144 states seen.
  EXPECT_EQ(report.states_seen, 2L * 16 * 192);
  EXPECT_EQ(report.scenes_completed, 2);
  EXPECT_EQ(report.recorded, 3000);
  EXPECT_EQ(report.jittered, 6000);
  ASSERT_EQ(s.stretches.rows(), 9000);
  double max_deformation = 0, max_rate = 0;
  for (Eigen::Index j = 0; j < s.stretches.rows(); ++j) {
    const Vec3 sigma = s.stretches.row(j).transpose(), rate = s.stretch_rates.row(j).transpose();
    ASSERT_GE(sigma[0], sigma[1]);
    ASSERT_GE(sigma[1], sigma[2]);
    ASSERT_EQ(s.targets.row(j).transpose(), teacher.correction(sigma, rate));
    if (j < report.recorded) {
      max_deformation = std::max(max_deformation, (sigma - Vec3::Ones()).cwiseAbs().maxCoeff());
      max_rate = std::max(max_rate, rate.cwiseAbs().maxCoeff());
    }
  }
  // The bar really moves: stretches of a few per cent and non-zero rates were recorded.
  EXPECT_GT(max_deformation, 5e-3);
  EXPECT_GT(max_rate, 1e-2);

  // Same seed, same samples.
  const StressSamples again = distillation_samples(bar, factors, teacher, o);
  EXPECT_EQ(again.stretches, s.stretches);
  EXPECT_EQ(again.targets, s.targets);
}

TEST(DistillationSamples, DistilledNetworkFollowsTheTeacherOnSimulatedStates) {
  // End to end on simulated states: the network trained on the bar's states (plus jitter)
  // reproduces the RBF teacher there (measured in docs/learning.md; bound 5 % as above).
  const auto teacher = smooth_teacher();
  const std::vector<double> factors { 0.5, 1.0, 2.0 };
  DistillationSampleOptions so;
  so.recorded_samples = 4000;
  const StressSamples s = distillation_samples(swinging_bar(), factors, teacher, so);
  const NnDistillationResult r = distill_nn_correction(s, {});
  std::cout << "simulated: epochs " << r.training.epochs << " (best " << r.training.best_epoch
            << "), relative RMS train " << r.relative_training_rms() << " validation "
            << r.relative_validation_rms() << ", " << r.training.seconds << " s\n";
  EXPECT_LT(r.relative_validation_rms(), 0.05);
}

TEST(NnDistillation, TeacherDampingIsCarriedOverExactly) {
  // The network fits N only; Δα₁ of an RBF teacher travels unchanged (damping_part), so the
  // network correction's stiffness damping equals the teacher's bit for bit, and its N is the
  // network's alone.
  const auto teacher = smooth_teacher();
  const NnDistillationResult r = distill_nn_correction(random_samples(teacher, 600, 3), {});
  EXPECT_EQ(r.correction.stiffness_damping(Vec3(1.1, 1, 0.9)), 0);
  const material::NnCorrection damped = with_teacher_damping(r.correction, teacher);
  ASSERT_NE(damped.parameters().damping, nullptr);
  EXPECT_FALSE(damped.parameters().damping->has_elastic_part());
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0.8, 1.2), g(-2, 2);
  for (int i = 0; i < 20; ++i) {
    const Vec3 sigma(u(rng), u(rng), u(rng)), rate(g(rng), g(rng), g(rng));
    EXPECT_EQ(damped.stiffness_damping(sigma), teacher.stiffness_damping(sigma));
    EXPECT_EQ(damped.correction(sigma, rate), r.correction.correction(sigma, rate));
  }
  EXPECT_NE(teacher.stiffness_damping(Vec3(1.1, 1, 0.9)), 0);
  // Δα₀ travels with the damping RBF, also when it is the teacher's only damping.
  EXPECT_EQ(damped.mass_damping(), teacher.mass_damping());
  auto mass_only = teacher.parameters();
  mass_only.damping_weights.resize(0);
  mass_only.damping_constant = 0;
  mass_only.mass_damping = -0.25;
  EXPECT_EQ(
      with_teacher_damping(r.correction, material::RbfCorrection(mass_only)).mass_damping(), -0.25);
  // A network teacher passes its damping on; a teacher without damping gives none.
  EXPECT_EQ(
      with_teacher_damping(r.correction, damped).parameters().damping, damped.parameters().damping);
  EXPECT_EQ(with_teacher_damping(damped, material::AnalyticCorrection({ 1e3, 0, 0 }))
                .parameters()
                .damping,
      nullptr);
  // The network's damping must not carry an elastic part.
  material::NnCorrection::Parameters bad = r.correction.parameters();
  bad.damping = std::make_shared<const material::RbfCorrection>(teacher);
  try {
    const material::NnCorrection c(bad);
    ADD_FAILURE() << "a damping RBF with an elastic part was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nn_correction.damping"), std::string::npos) << e.what();
  }
}

// ---- energy network -----------------------------------------------------------------------

namespace {

/// N of the energy Ψ = (10³/6) Σ_k ln cosh(6 e_k) + 10⁴ (Σ e)⁴, e = σ − 1: N_k = 10³ tanh(6 e_k)
/// + 4·10⁴ (Σe)³. Not a cubic energy, so the energy network's polynomial leaves a residual
/// (tanh's e³, e⁵ terms and the quartic) that only its MLP can fit.
class KnownEnergy final : public material::Correction {
  public:
  std::string name() const override { return "known_energy"; }
  Vec3 correction(const Vec3& s, const Vec3&) const override {
    const Vec3 e = s - Vec3::Ones();
    const double p1 = e.sum();
    return (1e3 * (6 * e.array()).tanh() + 4e4 * p1 * p1 * p1).matrix();
  }
  void correction_gradient(const Vec3&, const Vec3&, Mat3&, Mat3&) const override {
    ADD_FAILURE() << "not needed";
  }
  bool depends_on_rates() const override { return false; }
  std::unique_ptr<Correction> clone() const override { return std::make_unique<KnownEnergy>(); }
};

} // namespace

TEST(NnDistillation, EnergyNetworkFitsAKnownEnergyThroughItsGradient) {
  // The network sees only N (stresses), never Ψ: its gradient must reproduce them. Measured
  // (8-8 squareplus): validation 2.6 % of the target RMS (training 0.8 %); the polynomial alone
  // (the same network with its output layer zeroed) leaves 31 %: the MLP must remove most of it.
  // Bounds 4 % and a factor 7, with margin for other compilers' rounding.
  const KnownEnergy truth;
  const StressSamples samples = random_samples(truth, 6000, 17);
  const NnDistillationOptions o = energy_distillation_options();
  const NnDistillationResult r = distill_nn_correction(samples, o);
  material::NnCorrection::Parameters poly = r.correction.parameters();
  poly.layers.back().weight.setZero();
  poly.layers.back().bias.setZero();
  const material::NnCorrection polynomial_only(poly);
  double poly_sum = 0;
  for (Eigen::Index j = 0; j < samples.stretches.rows(); ++j) {
    const Vec3 s = samples.stretches.row(j).transpose();
    poly_sum += (polynomial_only.correction(s, Vec3::Zero()) - samples.targets.row(j).transpose())
                    .squaredNorm();
  }
  const double poly_rms = std::sqrt(poly_sum / double(samples.stretches.rows())) / r.target_rms;
  std::cout << "energy network: epochs " << r.training.epochs << ", " << r.training.seconds
            << " s, relative RMS train " << r.relative_training_rms() << " validation "
            << r.relative_validation_rms() << ", polynomial alone " << poly_rms << "\n";
  EXPECT_EQ(r.correction.parameters().kind, material::NnKind::Energy);
  EXPECT_LT(r.relative_validation_rms(), 0.04);
  EXPECT_LT(r.relative_validation_rms(), poly_rms / 7);
  // Same seed, same network.
  EXPECT_EQ(distill_nn_correction(samples, o).correction.parameters().layers[1].weight,
      r.correction.parameters().layers[1].weight);
}

TEST(NnDistillation, DistilRbfPicksTheKindFromTheTeacherAndCarriesItsDamping) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0.85, 1.15);
  MatX stretches(1500, 3);
  for (Eigen::Index i = 0; i < stretches.size(); ++i)
    stretches.data()[i] = u(rng);
  material::RbfCorrection::Parameters p = smooth_teacher().parameters();
  p.energy_kernels = true;
  const material::RbfCorrection energy_teacher(p);
  const RbfDistillationOptions defaults; // energy network for an energy teacher
  const NnDistillationResult r = distill_rbf(energy_teacher, stretches, defaults);
  std::cout << "distil_rbf (energy): relative RMS validation " << r.relative_validation_rms()
            << ", " << r.training.epochs << " epochs\n";
  EXPECT_EQ(r.correction.parameters().kind, material::NnKind::Energy);
  EXPECT_EQ(r.training_samples + r.validation_samples, 3000); // 1500 + 1500 jittered
  EXPECT_LT(r.relative_validation_rms(), 0.05);
  for (const Vec3& s : { Vec3(1.1, 1.0, 0.9), Vec3(0.92, 1.05, 1.12) })
    EXPECT_EQ(r.correction.stiffness_damping(s), energy_teacher.stiffness_damping(s));

  RbfDistillationOptions stress;
  stress.kind = material::NnKind::Stress;
  stress.jitter_copies = 0;
  const NnDistillationResult rs = distill_rbf(smooth_teacher(), stretches, stress);
  EXPECT_EQ(rs.correction.parameters().kind, material::NnKind::Stress);
  EXPECT_EQ(rs.training_samples + rs.validation_samples, 1500);
  EXPECT_LT(rs.relative_validation_rms(), 0.05);
  EXPECT_NE(rs.correction.parameters().damping, nullptr);

  EXPECT_THROW(distill_rbf(energy_teacher, MatX::Ones(5, 2), defaults), InputError);
  NnDistillationOptions bad = energy_distillation_options();
  bad.training.batch_norm = true;
  EXPECT_THROW(distill_nn_correction(random_samples(energy_teacher, 100, 1), bad), InputError);
}

TEST(NnDistillation, TeacherTailsAreTheEnergyNetworksPolynomialExactly) {
  // An energy RBF's linear and quadratic tails as the polynomial c: the energy network with a
  // zero MLP reproduces the tails' N (kernel weights zero) to rounding, and ΔΨ up to a constant.
  material::RbfCorrection::Parameters p = smooth_teacher().parameters();
  p.energy_kernels = true;
  p.weights.setZero();
  p.constant = 700;
  p.quadratic = Eigen::Vector4d(3e4, 2e4, 1e4, -1e4); // an energy tail: q₁ = 2 q₂
  const material::RbfCorrection tails(p);
  const auto c = rbf_energy_polynomial(tails);
  ASSERT_TRUE(c.has_value());
  material::NnCorrection::Parameters n;
  n.kind = material::NnKind::Energy;
  n.input_mean = VecX::Zero(3);
  n.input_scale = VecX::Ones(3);
  n.polynomial = *c;
  n.layers.push_back({ MatX::Zero(1, 3), VecX::Zero(1) });
  const material::NnCorrection net(n);
  const Vec3 rest = Vec3::Ones();
  for (const Vec3& s : { Vec3(1.1, 0.95, 0.9), Vec3(1.3, 1.3, 0.7), Vec3(0.8, 1.0, 1.25) }) {
    const Vec3 expected = tails.correction(s, Vec3::Zero());
    EXPECT_LE((net.correction(s, Vec3::Zero()) - expected).norm(), 1e-9 * expected.norm());
    EXPECT_NEAR(net.elastic_energy(s) - net.elastic_energy(rest),
        tails.elastic_energy(s) - tails.elastic_energy(rest),
        1e-9 * std::abs(tails.elastic_energy(s)));
  }
  p.neo_hookean = Eigen::Vector2d(1e3, 0);
  EXPECT_FALSE(rbf_energy_polynomial(material::RbfCorrection(p)).has_value());
  EXPECT_FALSE(rbf_energy_polynomial(smooth_teacher()).has_value()); // stress kernels
}
