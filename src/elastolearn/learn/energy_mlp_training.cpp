#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/energy_mlp_training.hpp>

#include <tbb/parallel_for.h>

#include <numeric>

namespace elastolearn::learn {

// Named, not anonymous: GradientLoss::Chunk (a class with linkage) holds these.
namespace energy_mlp_detail {

/// Forward buffers of one layer over a batch (B columns): pre-activation Z, f(Z), f'(Z), f''(Z),
/// and per input c the pre-activation tangent U_c = ∂Z/∂x_c and the activation tangent
/// T_c = f'(Z) ⊙ U_c. The output layer uses Z and T only (T_c = its input gradient).
struct Forward {
  MatX z, a, d1, d2;
  std::vector<MatX> u, t;
};

} // namespace energy_mlp_detail

namespace {

using energy_mlp_detail::Forward;

constexpr FieldErrors energy_mlp_training_error("mlp_training");

/// Forward pass with input tangents over the columns of x (d × B); `f` has one entry per layer.
void forward(const BatchNormMlp& net, ConstRef<MatX> x, std::vector<Forward>& f) {
  const int d = net.inputs();
  const std::size_t layers = net.layers.size();
  const Eigen::Index n = x.cols();
  for (std::size_t k = 0; k < layers; ++k) {
    const auto& l = net.layers[k];
    Forward& w = f[k];
    w.u.resize(std::size_t(d));
    w.t.resize(std::size_t(d));
    const bool last = k + 1 == layers;
    if (k == 0)
      w.z.noalias() = l.weight * x;
    else
      w.z.noalias() = l.weight * f[k - 1].a;
    w.z.colwise() += l.bias;
    for (int c = 0; c < d; ++c) {
      if (k == 0)
        w.u[std::size_t(c)] = l.weight.col(c).replicate(1, n);
      else
        w.u[std::size_t(c)].noalias() = l.weight * f[k - 1].t[std::size_t(c)];
    }
    if (last) {
      for (int c = 0; c < d; ++c)
        w.t[std::size_t(c)] = w.u[std::size_t(c)];
      continue;
    }
    w.a.resize(w.z.rows(), n);
    w.d1.resize(w.z.rows(), n);
    w.d2.resize(w.z.rows(), n);
    for (Eigen::Index i = 0; i < w.z.size(); ++i) {
      const material::ActivationValues v
          = material::activation_values(net.activation, w.z.data()[i]);
      w.a.data()[i] = v.f;
      w.d1.data()[i] = v.d1;
      w.d2.data()[i] = v.d2;
    }
    for (int c = 0; c < d; ++c)
      w.t[std::size_t(c)] = w.d1.cwiseProduct(w.u[std::size_t(c)]);
  }
}

/// D_jᵀ ∇g for the columns of a forward pass, into `s` (m × B).
void stress_of(const std::vector<Forward>& f, ConstRef<MatX> maps, int d, int m, MatX& s) {
  const Forward& out = f.back();
  s.setZero(m, maps.cols());
  for (int i = 0; i < m; ++i)
    for (int c = 0; c < d; ++c)
      s.row(i) += maps.row(c + d * i).cwiseProduct(out.t[std::size_t(c)].row(0));
}

/// The columns [begin, end) of `chunk` of `chunks` equal parts of n columns.
std::pair<Eigen::Index, Eigen::Index> chunk_columns(Eigen::Index n, int chunk, int chunks) {
  return { n * chunk / chunks, n * (chunk + 1) / chunks };
}

void check_set(const char* field, const GradientSamples& s, int d, int m) {
  if (s.inputs.cols() < 1)
    energy_mlp_training_error(field, "is empty");
  if (s.inputs.rows() != d || s.maps.rows() != d * m || s.targets.rows() != m
      || s.maps.cols() != s.inputs.cols() || s.targets.cols() != s.inputs.cols()) {
    energy_mlp_training_error(field,
        "inputs " + to_text(s.inputs.rows()) + " × " + to_text(s.inputs.cols()) + ", maps "
            + to_text(s.maps.rows()) + " × " + to_text(s.maps.cols()) + " and targets "
            + to_text(s.targets.rows()) + " × " + to_text(s.targets.cols())
            + " do not match (d inputs, d·m map rows, m targets, one column per sample)");
  }
  if (!s.inputs.allFinite() || !s.maps.allFinite() || !s.targets.allFinite())
    energy_mlp_training_error(field, "contains a non-finite value");
}

} // namespace

/// Buffers of one chunk: its forward pass, the adjoints of each layer's activation (Ā) and
/// activation tangents (T̄_c), and the chunk's share of the gradient.
struct GradientLoss::Chunk {
  std::vector<energy_mlp_detail::Forward> f;
  std::vector<MatX> a_bar;
  std::vector<std::vector<MatX>> t_bar;
  MatX residual, z_bar, u_bar;
  Eigen::RowVectorXd g_bar;
  MlpGradient gradient;
};

GradientLoss::GradientLoss()
    : m_chunks(std::size_t(kChunks)) { }
GradientLoss::~GradientLoss() = default;

const MlpGradient& GradientLoss::gradient(const BatchNormMlp& net, const GradientSamples& s) {
  const int d = net.inputs();
  const int m = static_cast<int>(s.targets.rows());
  const Eigen::Index n = s.inputs.cols();
  const std::size_t layers = net.layers.size();
  // ∂L/∂(∂g/∂x_c) per sample: (2/(m·n)) Σ_i D(c, i) r_i.
  const double scale = 2.0 / double(m * n);
  tbb::parallel_for(0, kChunks, [&](int chunk) {
    const auto [begin, end] = chunk_columns(n, chunk, kChunks);
    const Eigen::Index cols = end - begin;
    const auto x = s.inputs.middleCols(begin, cols);
    const auto maps = s.maps.middleCols(begin, cols);
    Chunk& w = m_chunks[std::size_t(chunk)];
    w.f.resize(layers);
    w.a_bar.resize(layers);
    if (w.t_bar.size() != layers || w.t_bar.front().size() != std::size_t(d)) // once per shape
      w.t_bar.assign(layers, std::vector<MatX>(std::size_t(d)));
    w.gradient.weights.resize(layers);
    w.gradient.biases.resize(layers);
    auto& grad_w = w.gradient.weights;
    auto& grad_b = w.gradient.biases;
    forward(net, x, w.f);
    stress_of(w.f, maps, d, m, w.residual);
    w.residual -= s.targets.middleCols(begin, cols);
    const std::size_t K = layers - 1;
    const auto& last = net.layers[K];
    grad_w[K].setZero(1, last.weight.cols());
    grad_b[K].setZero(1);
    for (int c = 0; c < d; ++c) {
      w.g_bar.setZero(cols);
      for (int i = 0; i < m; ++i)
        w.g_bar += scale * maps.row(c + d * i).cwiseProduct(w.residual.row(i));
      // ∂g/∂x_c = w_K T_{K−1,c} (or w_K e_c without hidden layers).
      if (K > 0) {
        grad_w[K].noalias() += w.g_bar * w.f[K - 1].t[std::size_t(c)].transpose();
        w.t_bar[K - 1][std::size_t(c)].noalias() = last.weight.transpose() * w.g_bar;
      } else {
        grad_w[K](0, c) += w.g_bar.sum();
      }
    }
    if (K > 0)
      w.a_bar[K - 1].setZero(last.weight.cols(), cols); // g's value is not in the loss
    for (std::size_t k = K; k-- > 0;) {
      const auto& l = net.layers[k];
      const Forward& fk = w.f[k];
      // Z̄ = f' ⊙ Ā + f'' ⊙ Σ_c T̄_c ⊙ U_c;  Ū_c = f' ⊙ T̄_c.
      w.z_bar = fk.d1.cwiseProduct(w.a_bar[k]);
      for (int c = 0; c < d; ++c)
        w.z_bar
            += fk.d2.cwiseProduct(w.t_bar[k][std::size_t(c)].cwiseProduct(fk.u[std::size_t(c)]));
      grad_b[k] = w.z_bar.rowwise().sum();
      if (k == 0)
        grad_w[k].noalias() = w.z_bar * x.transpose();
      else
        grad_w[k].noalias() = w.z_bar * w.f[k - 1].a.transpose();
      for (int c = 0; c < d; ++c) {
        w.u_bar = fk.d1.cwiseProduct(w.t_bar[k][std::size_t(c)]);
        if (k == 0) {
          grad_w[k].col(c) += w.u_bar.rowwise().sum(); // T_{−1,c} = e_c
        } else {
          grad_w[k].noalias() += w.u_bar * w.f[k - 1].t[std::size_t(c)].transpose();
          w.t_bar[k - 1][std::size_t(c)].noalias() = l.weight.transpose() * w.u_bar;
        }
      }
      if (k > 0)
        w.a_bar[k - 1].noalias() = l.weight.transpose() * w.z_bar;
    }
  });
  // Summed in chunk order, so the result does not depend on the threads that ran them.
  MlpGradient& total = m_chunks.front().gradient;
  for (std::size_t chunk = 1; chunk < m_chunks.size(); ++chunk)
    for (std::size_t k = 0; k < layers; ++k) {
      total.weights[k] += m_chunks[chunk].gradient.weights[k];
      total.biases[k] += m_chunks[chunk].gradient.biases[k];
    }
  return total;
}

MatX network_stress(const BatchNormMlp& net, const GradientSamples& s) {
  const int m = static_cast<int>(s.targets.rows());
  MatX stress(m, s.inputs.cols());
  const Eigen::Index n = s.inputs.cols();
  const int chunks = static_cast<int>(std::min<Eigen::Index>(n, GradientLoss::kChunks));
  tbb::parallel_for(0, chunks, [&](int chunk) {
    const auto [begin, end] = chunk_columns(n, chunk, chunks);
    std::vector<Forward> f(net.layers.size());
    forward(net, s.inputs.middleCols(begin, end - begin), f);
    MatX part;
    stress_of(f, s.maps.middleCols(begin, end - begin), net.inputs(), m, part);
    stress.middleCols(begin, end - begin) = part;
  });
  return stress;
}

double gradient_loss(const BatchNormMlp& net, const GradientSamples& s) {
  return (network_stress(net, s) - s.targets).squaredNorm() / double(s.targets.size());
}

MlpTrainingResult train_gradient_mlp(
    const GradientSamples& train, const GradientSamples& valid, const MlpTrainingOptions& o) {
  o.validate();
  if (o.batch_norm)
    energy_mlp_training_error(
        "batch_norm", "is not supported when training a network by its gradient");
  const auto start = Clock::now();
  const int d = static_cast<int>(train.inputs.rows());
  const int m = static_cast<int>(train.targets.rows());
  if (d < 1 || m < 1)
    energy_mlp_training_error("training", "needs ≥ 1 input and target row");
  check_set("training", train, d, m);
  check_set("validation", valid, d, m);

  BatchNormMlp net = make_batch_norm_mlp(d, o.hidden_widths, 1, false, o.seed);
  net.activation = o.activation;
  const std::size_t layers = net.layers.size();
  const Eigen::Index n = train.inputs.cols();
  const Eigen::Index batch = std::min<Eigen::Index>(o.batch_size, n);
  if (batch < 2)
    energy_mlp_training_error("training", "needs ≥ 2 samples, got " + to_text(n));
  const Eigen::Index batches = n / batch;

  std::vector<AdamMoments> adam_w, adam_b;
  for (const auto& l : net.layers) {
    adam_w.emplace_back(l.weight);
    adam_b.emplace_back(MatX(l.bias));
  }
  GradientSamples samples { MatX(d, batch), MatX(d * m, batch), MatX(m, batch) };
  GradientLoss loss;
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(o.seed ^ 0x9e3779b97f4a7c15ULL);

  MlpTrainingResult result { net, {} };
  EarlyStopping stopping { gradient_loss(net, valid) };
  double learning_rate = o.learning_rate;
  long steps = 0;
  for (int epoch = 1; epoch <= o.max_epochs; ++epoch) {
    shuffle_in_place(order, rng);
    for (Eigen::Index bi = 0; bi < batches; ++bi) {
      for (Eigen::Index j = 0; j < batch; ++j) {
        const Eigen::Index s = order[static_cast<std::size_t>(bi * batch + j)];
        samples.inputs.col(j) = train.inputs.col(s);
        samples.maps.col(j) = train.maps.col(s);
        samples.targets.col(j) = train.targets.col(s);
      }
      const MlpGradient& g = loss.gradient(net, samples);
      const double step = adam_step(o, learning_rate, ++steps);
      for (std::size_t k = 0; k < layers; ++k) {
        adam_update(net.layers[k].weight, g.weights[k], adam_w[k], o, step);
        if (k + 1 < layers)
          adam_update(net.layers[k].bias, g.biases[k], adam_b[k], o, step);
      }
    }
    const double validation_loss = gradient_loss(net, valid);
    if (!std::isfinite(validation_loss)) {
      energy_mlp_training_error("learning_rate",
          "training diverged at epoch " + to_text(epoch) + " (validation loss "
              + to_text(validation_loss) + "); lower the learning rate");
    }
    result.report.validation_history.push_back(validation_loss);
    result.report.epochs = epoch;
    bool stop = false;
    if (stopping.update(validation_loss, o, learning_rate, stop)) {
      result.network = net;
      result.report.best_epoch = epoch;
    }
    if (stop) {
      result.report.stopped_early = epoch < o.max_epochs;
      break;
    }
  }
  result.report.validation_loss = stopping.best;
  result.report.training_loss = gradient_loss(result.network, train);
  result.report.seconds = seconds_since(start);
  return result;
}

} // namespace elastolearn::learn
