#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/nn_distillation.hpp>
#include <elastolearn/sim/amplified_scene.hpp>
#include <elastolearn/sim/run_simulation.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors distillation_error("distillation");

using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Sample j in stable descending stretch order, rates and target permuted alike (the order
/// principal_frame reports; the corrections themselves are permutation-equivariant).
void sorted_sample(const StressSamples& samples, Eigen::Index j, Vec3& s, Vec3& f, Vec3& y) {
  const Vec3 s0 = samples.stretches.row(j).transpose();
  std::array<int, 3> p { 0, 1, 2 };
  std::stable_sort(p.begin(), p.end(), [&](int a, int b) { return s0[a] > s0[b]; });
  for (int i = 0; i < 3; ++i) {
    s[i] = s0[p[i]];
    f[i] = samples.stretch_rates(j, p[i]);
    y[i] = samples.targets(j, p[i]);
  }
}

/// Row-wise mean and standard deviation over the columns of `m`; a (numerically) constant row
/// gets scale 1 so that standardisation stays finite.
void row_statistics(const MatX& m, VecX& mean, VecX& scale) {
  mean = m.rowwise().mean();
  scale = ((m.colwise() - mean).rowwise().squaredNorm() / double(m.cols())).cwiseSqrt();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    if (!(scale[r] > 1e-12 * std::max(1.0, std::abs(mean[r]))))
      scale[r] = 1;
  }
}

/// RMS over the states `states` of ‖N(σ_j, ḟ_j) − N_teacher,j‖ [Pa] (one state = 3 directions).
double rms_error(
    const material::Correction& n, const StressSamples& samples, const std::vector<int>& states) {
  double sum = 0;
  for (int j : states) {
    const Vec3 out = n.correction(
        samples.stretches.row(j).transpose(), samples.stretch_rates.row(j).transpose());
    sum += (out - samples.targets.row(j).transpose()).squaredNorm();
  }
  return std::sqrt(sum / double(states.size()));
}

/// The training rows of the states `states`: per state and direction k, x = nn_input(σ, ḟ, k)
/// (a column of `inputs`, 6 × 3·|states|) and N_teacher,k (an entry of `targets`, 1 × …).
void direction_rows(
    const StressSamples& samples, const std::vector<int>& states, MatX& inputs, MatX& targets) {
  const auto rows = static_cast<Eigen::Index>(3 * states.size());
  inputs.resize(6, rows);
  targets.resize(1, rows);
  Eigen::Index c = 0;
  for (int j : states) {
    const Vec3 s = samples.stretches.row(j).transpose();
    const Vec3 f = samples.stretch_rates.row(j).transpose();
    for (int k = 0; k < 3; ++k, ++c) {
      inputs.col(c) = material::nn_input(s, f, k);
      targets(0, c) = samples.targets(j, k);
    }
  }
}

} // namespace

void DistillationSampleOptions::validate() const {
  if (recorded_samples < 1)
    distillation_error("recorded_samples", "must be ≥ 1, got " + to_text(recorded_samples));
  if (frame_stride < 1)
    distillation_error("frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  if (jitter_copies < 0)
    distillation_error("jitter_copies", "must be ≥ 0, got " + to_text(jitter_copies));
  if (!std::isfinite(stretch_jitter) || stretch_jitter < 0)
    distillation_error("stretch_jitter", "must be finite and ≥ 0, got " + to_text(stretch_jitter));
  if (!std::isfinite(rate_jitter) || rate_jitter < 0)
    distillation_error("rate_jitter", "must be finite and ≥ 0, got " + to_text(rate_jitter));
  if (std::isnan(stretch_min) || std::isnan(stretch_max) || !(stretch_min <= stretch_max))
    distillation_error("stretch_min", "must be ≤ stretch_max");
}

void NnDistillationOptions::validate() const {
  training.validate();
  if (energy_polynomial_degree != 0 && energy_polynomial_degree != 2
      && energy_polynomial_degree != 3)
    distillation_error(
        "energy_polynomial_degree", "must be 0, 2 or 3, got " + to_text(energy_polynomial_degree));
  if (kind == material::NnKind::Energy && training.batch_norm)
    distillation_error(
        "training.batch_norm", "must be off for an energy network (train_gradient_mlp)");
  if (!(validation_fraction > 0 && validation_fraction < 1))
    distillation_error(
        "validation_fraction", "must be in (0, 1), got " + to_text(validation_fraction));
}

StressSamples distillation_samples(std::span<const sim::Scene> scenes,
    const material::Correction& teacher, const DistillationSampleOptions& o,
    DistillationSampleReport* report_out) {
  o.validate();
  if (scenes.empty())
    distillation_error("scenes", "no scene to simulate");
  DistillationSampleReport report;
  const Eigen::Index k = o.recorded_samples;
  Rows3 stretches(k, 3), rates(k, 3);
  std::mt19937_64 rng(o.seed);
  long seen = 0;
  const std::shared_ptr<const material::Correction> shared_teacher = teacher.clone();
  const bool bounded = std::isfinite(o.stretch_min) || std::isfinite(o.stretch_max);

  // The simulations run side by side and keep their recorded frames; the sampling below then
  // visits the states in scene, frame and element order, so the result does not depend on the
  // threads.
  struct Recorded {
    std::vector<VecX> positions, velocities;
    sim::SimulationReport run;
  };
  std::vector<Recorded> recorded_runs(scenes.size());
  tbb::parallel_for(std::size_t(0), scenes.size(), [&](std::size_t i) {
    sim::Scene scene = scenes[i];
    scene.material.correction = shared_teacher;
    // A sampling run only collects states: where a step fails it stops instead of rescuing the
    // step (exact tangent, substeps). The states past a failing step are where the teacher is
    // least trustworthy, and a stalled run's rescues cost more than the run.
    scene.newton.retry_exact_tangent = false;
    scene.newton.max_step_halvings = 0;
    Recorded& r = recorded_runs[i];
    r.run = sim::run_simulation(scene, [&](int frame, double, const VecX& x, const VecX& v) {
      if (frame % o.frame_stride != 0)
        return;
      r.positions.push_back(x);
      r.velocities.push_back(v);
    });
  });
  std::vector<ElementState> states;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const sim::Scene& scene = scenes[i];
    const ReconstructionMesh mesh(scene.mesh);
    Recorded& r = recorded_runs[i];
    for (std::size_t frame = 0; frame < r.positions.size(); ++frame) {
      compute_element_states(mesh, r.positions[frame], r.velocities[frame], states);
      // Reservoir sampling (Algorithm R) over the states in the stretch interval: state i
      // replaces slot j < k with j uniform in [0, i].
      for (const ElementState& state : states) {
        const Vec3& sigma = state.frame.stretches;
        if (bounded && (sigma.minCoeff() < o.stretch_min || sigma.maxCoeff() > o.stretch_max))
          continue;
        Eigen::Index slot = seen++;
        if (slot >= k) {
          slot = static_cast<Eigen::Index>(uniform01(rng) * double(slot + 1));
          if (slot >= k)
            continue;
        }
        stretches.row(slot) = sigma.transpose();
        rates.row(slot) = state.stretch_rates.transpose();
      }
    }
    r.positions = {}; // the frames are sampled
    r.velocities = {};
    if (r.run.completed)
      ++report.scenes_completed;
    else
      report.messages.push_back(scene.name + ": " + r.run.message);
  }
  report.states_seen = seen;
  const Eigen::Index recorded = std::min<Eigen::Index>(k, seen);
  if (recorded == 0)
    distillation_error("scenes", "the simulations recorded no element state");
  report.recorded = static_cast<int>(recorded);

  // Jittered copies around the recorded states.
  const Eigen::Index total = recorded * (1 + o.jitter_copies);
  StressSamples out;
  out.stretches.resize(total, 3);
  out.stretch_rates.resize(total, 3);
  out.targets.resize(total, 3);
  out.stretches.topRows(recorded) = stretches.topRows(recorded);
  out.stretch_rates.topRows(recorded) = rates.topRows(recorded);
  const double rate_rms = std::sqrt(rates.topRows(recorded).squaredNorm() / double(3 * recorded));
  const double rate_sigma = o.rate_jitter * rate_rms;
  for (Eigen::Index j = recorded; j < total; ++j) {
    const Eigen::Index src = j % recorded;
    for (int i = 0; i < 3; ++i) {
      out.stretches(j, i) = std::clamp(stretches(src, i) + o.stretch_jitter * standard_normal(rng),
          o.stretch_min, o.stretch_max);
      out.stretch_rates(j, i) = rates(src, i) + rate_sigma * standard_normal(rng);
    }
  }
  report.jittered = static_cast<int>(total - recorded);
  // Stored in descending stretch order (a jitter may swap two stretches), then the teacher.
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, total, 1024),
      [&](const tbb::blocked_range<Eigen::Index>& rows) {
        for (Eigen::Index j = rows.begin(); j < rows.end(); ++j) {
          Vec3 s, f, unused;
          out.targets.row(j).setZero();
          sorted_sample(out, j, s, f, unused);
          out.stretches.row(j) = s.transpose();
          out.stretch_rates.row(j) = f.transpose();
          out.targets.row(j) = teacher.correction(s, f).transpose();
        }
      });
  if (!out.targets.allFinite())
    distillation_error("teacher", "the teacher correction returned a non-finite value");
  if (report_out)
    *report_out = std::move(report);
  return out;
}

material::NnCorrection with_teacher_damping(
    const material::NnCorrection& network, const material::Correction& teacher) {
  material::NnCorrection::Parameters p = network.parameters();
  p.damping.reset();
  if (const auto* rbf = dynamic_cast<const material::RbfCorrection*>(&teacher)) {
    if (rbf->has_damping())
      p.damping = std::make_shared<const material::RbfCorrection>(material::damping_part(*rbf));
  } else if (const auto* nn = dynamic_cast<const material::NnCorrection*>(&teacher)) {
    p.damping = nn->parameters().damping;
  } else if (teacher.stiffness_damping(Vec3::Ones()) != 0) {
    distillation_error("teacher",
        "a \"" + teacher.name() + "\" correction's damping cannot be carried over (only an RBF's)");
  }
  return material::NnCorrection(std::move(p));
}

StressSamples distillation_samples(const sim::Scene& scene, std::span<const double> motion_scales,
    const material::Correction& teacher, const DistillationSampleOptions& options,
    DistillationSampleReport* report) {
  const double one = 1.0;
  const std::vector<sim::Scene> scenes = scaled_motions(
      scene, motion_scales.empty() ? std::span<const double>(&one, 1) : motion_scales);
  return distillation_samples(std::span<const sim::Scene>(scenes), teacher, options, report);
}

std::vector<sim::Scene> scaled_motions(const sim::Scene& scene, std::span<const double> scales) {
  std::vector<sim::Scene> out;
  for (double a : scales) {
    if (!std::isfinite(a))
      distillation_error("motion_scales", "contains a non-finite factor " + to_text(a));
    sim::Scene s = sim::amplified_scene(scene, a);
    s.name = scene.name + "_x" + to_text(a);
    out.push_back(std::move(s));
  }
  return out;
}

namespace {

/// Checks `samples` and splits its states into a random validation set and a training set
/// (o.validation_fraction), each sorted.
void split_states(const StressSamples& samples, const NnDistillationOptions& o,
    std::vector<int>& train, std::vector<int>& valid) {
  o.validate();
  const Eigen::Index n = samples.stretches.rows();
  if (samples.stretch_rates.rows() != n || samples.targets.rows() != n) {
    distillation_error("samples",
        to_text(n) + " stretch samples but " + to_text(samples.stretch_rates.rows())
            + " stretch rates and " + to_text(samples.targets.rows()) + " targets");
  }
  if (!samples.stretches.allFinite() || !samples.stretch_rates.allFinite()
      || !samples.targets.allFinite()) {
    distillation_error("samples", "contain a non-finite value");
  }
  // The split is over states, so that the three direction rows of a state are never on both
  // sides of it.
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(o.training.seed + 0x5bd1e995ULL);
  shuffle_in_place(order, rng);
  const auto n_valid = static_cast<std::size_t>(std::llround(o.validation_fraction * double(n)));
  if (n_valid < 2 || order.size() - n_valid < 2) {
    distillation_error("samples",
        to_text(n) + " samples leave fewer than 2 in the training or validation split "
            + "(validation_fraction " + to_text(o.validation_fraction) + ")");
  }
  valid.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n_valid));
  train.assign(order.begin() + static_cast<std::ptrdiff_t>(n_valid), order.end());
  // Training in sample order keeps the split independent of the shuffle inside the trainer.
  std::sort(valid.begin(), valid.end());
  std::sort(train.begin(), train.end());
}

/// The result's RMS errors of `correction` against the samples' targets.
NnDistillationResult measured(material::NnCorrection correction, const MlpTrainingReport& report,
    const StressSamples& samples, const std::vector<int>& train, const std::vector<int>& valid) {
  NnDistillationResult result { std::move(correction), report };
  result.training_samples = static_cast<int>(train.size());
  result.validation_samples = static_cast<int>(valid.size());
  result.training_rms = rms_error(result.correction, samples, train);
  result.validation_rms = rms_error(result.correction, samples, valid);
  result.target_rms = std::sqrt(samples.targets.squaredNorm() / double(samples.targets.rows()));
  return result;
}

/// ∇_σ m(p) of the energy polynomial m = (p₁, p₁², p₂, p₁³, p₁p₂, p₃) (NnKind::Energy): 3 × 6.
Eigen::Matrix<double, 3, 6> polynomial_stress_basis(const Vec3& stretches) {
  const Vec3 e = stretches - Vec3::Ones();
  const Vec3 p = material::power_sums(stretches);
  Eigen::Matrix<double, 3, 6> m;
  m.col(0).setOnes();
  m.col(1).setConstant(2 * p[0]);
  m.col(2) = 2 * e;
  m.col(3).setConstant(3 * p[0] * p[0]);
  m.col(4) = Vec3::Constant(p[1]) + 2 * p[0] * e;
  m.col(5) = 3 * e.cwiseProduct(e);
  return m;
}

} // namespace

NnDistillationOptions energy_distillation_options() {
  NnDistillationOptions o;
  o.kind = material::NnKind::Energy;
  o.training.hidden_widths = { 8, 8 };
  o.training.activation = material::Activation::Squareplus;
  o.training.batch_norm = false;
  o.training.learning_rate = 5e-3;
  o.training.patience = 40;
  return o;
}

NnDistillationResult distill_nn_correction(
    const StressSamples& samples, const NnDistillationOptions& o) {
  return o.kind == material::NnKind::Energy ? distill_energy_network(samples, o)
                                            : distill_stress_network(samples, o);
}

NnDistillationResult distill_stress_network(
    const StressSamples& samples, const NnDistillationOptions& o) {
  std::vector<int> train, valid;
  split_states(samples, o, train, valid);

  // One row per state and direction: the shared scalar network g is fitted to all three.
  MatX train_x, train_y, valid_x, valid_y;
  direction_rows(samples, train, train_x, train_y);
  direction_rows(samples, valid, valid_x, valid_y);
  VecX in_mean, in_scale, out_mean, out_scale;
  row_statistics(train_x, in_mean, in_scale);
  row_statistics(train_y, out_mean, out_scale);
  const auto standardise = [](MatX& m, const VecX& mean, const VecX& scale) {
    m = (m.colwise() - mean).array().colwise() / scale.array();
  };
  standardise(train_x, in_mean, in_scale);
  standardise(valid_x, in_mean, in_scale);
  standardise(train_y, out_mean, out_scale);
  standardise(valid_y, out_mean, out_scale);
  const MlpTrainingResult trained = train_mlp(train_x, train_y, valid_x, valid_y, o.training);

  material::NnCorrection::Parameters p;
  p.activation = o.training.activation;
  p.input_mean = in_mean;
  p.input_scale = in_scale;
  p.output_mean = out_mean[0];
  p.output_scale = out_scale[0];
  p.layers = fold_batch_norm(trained.network);
  return measured(material::NnCorrection(std::move(p)), trained.report, samples, train, valid);
}

NnDistillationResult distill_energy_network(
    const StressSamples& samples, const NnDistillationOptions& o) {
  if (o.training.batch_norm)
    distillation_error(
        "training.batch_norm", "must be off for an energy network (train_gradient_mlp)");
  std::vector<int> train, valid;
  split_states(samples, o, train, valid);
  const auto row = [&](int j) { return Vec3(samples.stretches.row(j).transpose()); };
  const auto target = [&](int j) { return Vec3(samples.targets.row(j).transpose()); };

  // The polynomial by linear least squares on the training states (columns scaled to unit norm
  // first: p₁³ is ~10⁻³ of p₁).
  const auto n_train = static_cast<Eigen::Index>(train.size());
  MatX basis(3 * n_train, 6);
  VecX rhs(3 * n_train);
  for (Eigen::Index j = 0; j < n_train; ++j) {
    const int s = train[std::size_t(j)];
    basis.middleRows<3>(3 * j) = polynomial_stress_basis(row(s));
    rhs.segment<3>(3 * j) = target(s);
  }
  VecX column_norm = basis.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < 6; ++c)
    if (!(column_norm[c] > 0))
      column_norm[c] = 1;
  const int terms = o.energy_polynomial_degree == 3 ? 6 : o.energy_polynomial_degree == 2 ? 3 : 0;
  Eigen::Matrix<double, 6, 1> polynomial = Eigen::Matrix<double, 6, 1>::Zero();
  if (o.energy_polynomial) {
    polynomial = *o.energy_polynomial;
  } else if (terms > 0) {
    const VecX scaled
        = (basis.leftCols(terms) * column_norm.head(terms).cwiseInverse().asDiagonal())
              .colPivHouseholderQr()
              .solve(rhs);
    polynomial.head(terms) = scaled.cwiseQuotient(column_norm.head(terms));
  }

  // Inputs x = energy_input(σ), standardised with the training states' statistics.
  MatX p_train(3, n_train);
  for (Eigen::Index j = 0; j < n_train; ++j)
    p_train.col(j) = material::energy_input(row(train[std::size_t(j)]));
  VecX in_mean, in_scale;
  row_statistics(p_train, in_mean, in_scale);
  // D = ∂x̃/∂σ = diag(1/s) (∂x/∂p)(∂p/∂σ), ∂p_j/∂σ_i = (1, 2e_i, 3e_i²)_j; D(c, i) at row c + 3i.
  const auto chain = [&](const Vec3& s, auto&& map) {
    const Vec3 e = s - Vec3::Ones();
    Mat3 x_p;
    material::energy_input(s, &x_p);
    for (int i = 0; i < 3; ++i) {
      const Vec3 p_sigma(1, 2 * e[i], 3 * e[i] * e[i]);
      for (int c = 0; c < 3; ++c)
        map(c + 3 * i) = x_p.row(c).dot(p_sigma) / in_scale[c];
    }
  };
  const auto gradient_samples = [&](const std::vector<int>& states, GradientSamples& g) {
    const auto n = static_cast<Eigen::Index>(states.size());
    g.inputs.resize(3, n);
    g.maps.resize(9, n);
    g.targets.resize(3, n);
    for (Eigen::Index j = 0; j < n; ++j) {
      const Vec3 s = row(states[std::size_t(j)]);
      g.inputs.col(j) = (material::energy_input(s) - in_mean).cwiseQuotient(in_scale);
      chain(s, [&](int r) -> double& { return g.maps(r, j); });
      g.targets.col(j) = target(states[std::size_t(j)]) - polynomial_stress_basis(s) * polynomial;
    }
  };
  GradientSamples train_set, valid_set;
  gradient_samples(train, train_set);
  gradient_samples(valid, valid_set);
  // Output scale: the residual's RMS over the map's, so that the MLP's input gradient is O(1).
  const double residual_rms
      = std::sqrt(train_set.targets.squaredNorm() / double(train_set.targets.size()));
  const double map_rms = std::sqrt(train_set.maps.squaredNorm() / double(train_set.maps.size()));
  const double output_scale = residual_rms > 0 ? residual_rms / map_rms : 1.0;
  train_set.targets /= output_scale;
  valid_set.targets /= output_scale;
  const MlpTrainingResult trained = train_gradient_mlp(train_set, valid_set, o.training);

  material::NnCorrection::Parameters p;
  p.kind = material::NnKind::Energy;
  p.activation = o.training.activation;
  p.input_mean = in_mean;
  p.input_scale = in_scale;
  p.output_scale = output_scale;
  p.polynomial = polynomial;
  p.layers = fold_batch_norm(trained.network);
  return measured(material::NnCorrection(std::move(p)), trained.report, samples, train, valid);
}

std::optional<Eigen::Matrix<double, 6, 1>> rbf_energy_polynomial(
    const material::RbfCorrection& rbf) {
  const auto& p = rbf.parameters();
  if (!p.energy_kernels || !p.neo_hookean.isZero(0))
    return std::nullopt;
  // N_k = a e_k + b (p₁ − e_k) + c is the gradient of ½(a − b) p₂ + ½ b p₁² + c p₁;
  // q = α(3, 6, 3, 0) + β(3, 2, 1, −2) + γ(3, 0, 0, 0) that of α p₁³ + β p₁p₂ + γ p₃.
  const Eigen::Vector4d& q = p.quadratic;
  const double beta = -0.5 * q[3], alpha = (q[2] - beta) / 3,
               gamma = (q[0] - 3 * alpha - 3 * beta) / 3;
  Eigen::Matrix<double, 6, 1> c;
  c << p.constant, 0.5 * p.other_slope, 0.5 * (p.own_slope - p.other_slope), alpha, beta, gamma;
  return c;
}

void RbfDistillationOptions::validate() const {
  if (jitter_copies < 0)
    distillation_error("jitter_copies", "must be ≥ 0, got " + to_text(jitter_copies));
  if (!std::isfinite(stretch_jitter) || stretch_jitter < 0)
    distillation_error("stretch_jitter", "must be finite and ≥ 0, got " + to_text(stretch_jitter));
  if (!std::isfinite(rate_sigma) || rate_sigma < 0)
    distillation_error("rate_sigma", "must be finite and ≥ 0, got " + to_text(rate_sigma));
  stress.validate();
  energy.validate();
}

NnDistillationResult distill_rbf(const material::RbfCorrection& teacher, ConstRef<MatX> stretches,
    const RbfDistillationOptions& o) {
  o.validate();
  if (stretches.cols() != 3 || stretches.rows() < 2)
    distillation_error("stretches",
        "expected n × 3 principal stretches with n ≥ 2, got " + to_text(stretches.rows()) + " × "
            + to_text(stretches.cols()));
  if (!stretches.allFinite())
    distillation_error("stretches", "contain a non-finite value");
  const material::NnKind kind = o.kind.value_or(
      teacher.parameters().energy_kernels ? material::NnKind::Energy : material::NnKind::Stress);
  const Eigen::Index n = stretches.rows(), total = n * (1 + o.jitter_copies);
  StressSamples samples;
  samples.stretches.resize(total, 3);
  samples.stretch_rates.setZero(total, 3);
  samples.targets.resize(total, 3);
  std::mt19937_64 rng(o.seed);
  for (Eigen::Index j = 0; j < total; ++j) {
    for (int i = 0; i < 3; ++i) {
      samples.stretches(j, i)
          = stretches(j % n, i) + (j < n ? 0.0 : o.stretch_jitter * standard_normal(rng));
      if (kind == material::NnKind::Stress)
        samples.stretch_rates(j, i) = o.rate_sigma * standard_normal(rng);
    }
    samples.targets.row(j)
        = teacher.elastic_correction(samples.stretches.row(j).transpose()).transpose();
  }
  if (!samples.targets.allFinite())
    distillation_error("teacher", "the teacher correction returned a non-finite value");
  NnDistillationOptions training = kind == material::NnKind::Energy ? o.energy : o.stress;
  if (kind == material::NnKind::Energy && o.teacher_polynomial && !training.energy_polynomial)
    training.energy_polynomial = rbf_energy_polynomial(teacher);
  NnDistillationResult r = distill_nn_correction(samples, training);
  r.correction = with_teacher_damping(r.correction, teacher);
  return r;
}

} // namespace elastolearn::learn
