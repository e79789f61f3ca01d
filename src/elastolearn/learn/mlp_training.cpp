#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/mlp_training.hpp>

#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors mlp_training_error("mlp_training");

/// Per-layer gradients, Adam state and batch buffers, allocated once per training run.
struct LayerWork {
  MatX d_weight, d_bias, d_gamma, d_beta; // gradients (bias etc. as column matrices)
  AdamMoments weight, bias, gamma, beta;
  MatX z; // pre-activation W a + b (out × B)
  MatX z_hat; // normalised pre-activation (batch norm only)
  MatX slope; // f'(y) (hidden layers)
  MatX activation; // f(y), the next layer's input (hidden layers)
  MatX grad; // ∂L/∂(layer output) (out × B), becomes ∂L/∂z in the backward pass
  VecX inv_std; // 1/√(var + ε) of the batch (batch norm only)
  LayerWork(const BatchNormMlp::Layer& l, Eigen::Index batch)
      : weight(l.weight)
      , bias(l.bias)
      , gamma(l.gamma)
      , beta(l.beta)
      , z(l.weight.rows(), batch) {
    if (l.has_batch_norm()) {
      z_hat.resize(l.weight.rows(), batch);
      inv_std.resize(l.weight.rows());
    }
    slope.resize(l.weight.rows(), batch);
    activation.resize(l.weight.rows(), batch);
    grad.resize(l.weight.rows(), batch);
  }
};

double mean_squared_error(const BatchNormMlp& net, ConstRef<MatX> x, ConstRef<MatX> y) {
  return (evaluate(net, x, BatchNormMode::Inference) - y).squaredNorm() / double(y.size());
}

void check_set(const char* field, ConstRef<MatX> x, ConstRef<MatX> y, int inputs, int outputs) {
  if (x.cols() < 1)
    mlp_training_error(field, "is empty");
  if (x.rows() != inputs || y.rows() != outputs || y.cols() != x.cols()) {
    mlp_training_error(field,
        "inputs " + to_text(x.rows()) + " × " + to_text(x.cols()) + " and targets "
            + to_text(y.rows()) + " × " + to_text(y.cols()) + " do not match (" + to_text(inputs)
            + " inputs, " + to_text(outputs) + " outputs, one column per sample)");
  }
  if (!x.allFinite() || !y.allFinite())
    mlp_training_error(field, "contains a non-finite value");
}

} // namespace

double uniform01(std::mt19937_64& rng) {
  return double(rng() >> 11) * 0x1.0p-53;
}

double standard_normal(std::mt19937_64& rng) {
  const double u = 1.0 - uniform01(rng); // (0, 1]: log is finite
  const double v = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
}

void shuffle_in_place(std::vector<int>& values, std::mt19937_64& rng) {
  for (std::size_t i = values.size(); i > 1; --i) {
    const auto j = std::min(static_cast<std::size_t>(uniform01(rng) * double(i)), i - 1);
    std::swap(values[i - 1], values[j]);
  }
}

double adam_step(const MlpTrainingOptions& o, double learning_rate, long steps) {
  return learning_rate * std::sqrt(1 - std::pow(o.beta2, double(steps)))
      / (1 - std::pow(o.beta1, double(steps)));
}

bool EarlyStopping::update(
    double loss, const MlpTrainingOptions& o, double& learning_rate, bool& stop) {
  stop = false;
  if (loss < (1 - o.min_improvement) * best) {
    best = loss;
    since_best = since_decay = 0;
    return true;
  }
  ++since_best;
  if (++since_decay >= o.plateau_epochs) {
    learning_rate *= 0.5;
    since_decay = 0;
  }
  stop = since_best >= o.patience;
  return false;
}

void MlpTrainingOptions::validate() const {
  if (hidden_widths.empty())
    mlp_training_error("hidden_widths", "is empty; at least one hidden layer is required");
  if (hidden_widths.size() > std::size_t(material::NnCorrection::max_hidden_layers)) {
    mlp_training_error("hidden_widths",
        "has " + to_text(hidden_widths.size()) + " layers, at most "
            + to_text(material::NnCorrection::max_hidden_layers) + " are supported");
  }
  for (int w : hidden_widths) {
    if (w < 1 || w > material::NnCorrection::max_width) {
      mlp_training_error("hidden_widths",
          "width " + to_text(w) + " outside 1.." + to_text(material::NnCorrection::max_width));
    }
  }
  if (batch_size < 2)
    mlp_training_error("batch_size", "must be ≥ 2, got " + to_text(batch_size));
  if (max_epochs < 1)
    mlp_training_error("max_epochs", "must be ≥ 1, got " + to_text(max_epochs));
  if (!(learning_rate > 0) || !std::isfinite(learning_rate))
    mlp_training_error("learning_rate", "must be finite and > 0, got " + to_text(learning_rate));
  if (!(beta1 >= 0 && beta1 < 1))
    mlp_training_error("beta1", "must be in [0, 1), got " + to_text(beta1));
  if (!(beta2 >= 0 && beta2 < 1))
    mlp_training_error("beta2", "must be in [0, 1), got " + to_text(beta2));
  if (!(adam_epsilon > 0) || !std::isfinite(adam_epsilon))
    mlp_training_error("adam_epsilon", "must be finite and > 0, got " + to_text(adam_epsilon));
  if (plateau_epochs < 1)
    mlp_training_error("plateau_epochs", "must be ≥ 1, got " + to_text(plateau_epochs));
  if (patience < 1)
    mlp_training_error("patience", "must be ≥ 1, got " + to_text(patience));
  if (!(min_improvement >= 0 && min_improvement < 1))
    mlp_training_error("min_improvement", "must be in [0, 1), got " + to_text(min_improvement));
  if (!(batch_norm_momentum > 0 && batch_norm_momentum <= 1))
    mlp_training_error(
        "batch_norm_momentum", "must be in (0, 1], got " + to_text(batch_norm_momentum));
  if (!(batch_norm_epsilon > 0) || !std::isfinite(batch_norm_epsilon))
    mlp_training_error(
        "batch_norm_epsilon", "must be finite and > 0, got " + to_text(batch_norm_epsilon));
}

BatchNormMlp make_batch_norm_mlp(int inputs, const std::vector<int>& hidden_widths, int outputs,
    bool batch_norm, std::uint64_t seed) {
  if (inputs < 1 || outputs < 1)
    mlp_training_error("network",
        "needs ≥ 1 input and output, got " + to_text(inputs) + " and " + to_text(outputs));
  for (int w : hidden_widths) {
    if (w < 1 || w > material::NnCorrection::max_width) {
      mlp_training_error("hidden_widths",
          "width " + to_text(w) + " outside 1.." + to_text(material::NnCorrection::max_width));
    }
  }
  std::mt19937_64 rng(seed);
  BatchNormMlp net;
  std::vector<int> widths = hidden_widths;
  widths.push_back(outputs);
  int in = inputs;
  for (std::size_t k = 0; k < widths.size(); ++k) {
    const int out = widths[k];
    BatchNormMlp::Layer l;
    // Glorot/Xavier uniform: U(−a, a), a = √(6 / (in + out)).
    const double a = std::sqrt(6.0 / double(in + out));
    l.weight.resize(out, in);
    for (Eigen::Index i = 0; i < l.weight.size(); ++i)
      l.weight.data()[i] = a * (2 * uniform01(rng) - 1);
    l.bias = VecX::Zero(out);
    if (batch_norm && k + 1 < widths.size()) {
      l.gamma = VecX::Ones(out);
      l.beta = VecX::Zero(out);
      l.running_mean = VecX::Zero(out);
      l.running_var = VecX::Ones(out);
    }
    net.layers.push_back(std::move(l));
    in = out;
  }
  return net;
}

MatX evaluate(const BatchNormMlp& net, ConstRef<MatX> x, BatchNormMode mode) {
  ELASTOLEARN_CHECK(x.rows() == net.inputs(), "evaluate: input rows do not match the network");
  MatX a = x;
  for (std::size_t k = 0; k < net.layers.size(); ++k) {
    const auto& l = net.layers[k];
    MatX z = l.weight * a;
    z.colwise() += l.bias;
    if (k + 1 == net.layers.size())
      return z;
    if (l.has_batch_norm()) {
      VecX mean = l.running_mean, var = l.running_var;
      if (mode == BatchNormMode::Training) {
        mean = z.rowwise().mean();
        var = (z.colwise() - mean).rowwise().squaredNorm() / double(z.cols());
      }
      const VecX scale = l.gamma.array() / (var.array() + net.batch_norm_epsilon).sqrt();
      z = ((z.colwise() - mean).array().colwise() * scale.array()).colwise() + l.beta.array();
    }
    const material::Activation f = net.activation;
    a = z.unaryExpr([f](double v) { return material::activation_values(f, v).f; });
  }
  return a; // unreachable: the last layer returns above
}

std::vector<material::NnCorrection::Layer> fold_batch_norm(const BatchNormMlp& net) {
  std::vector<material::NnCorrection::Layer> folded;
  for (const auto& l : net.layers) {
    material::NnCorrection::Layer f { l.weight, l.bias };
    if (l.has_batch_norm()) {
      const VecX s = l.gamma.array() / (l.running_var.array() + net.batch_norm_epsilon).sqrt();
      f.weight = s.asDiagonal() * l.weight;
      f.bias = s.cwiseProduct(l.bias - l.running_mean) + l.beta;
    }
    folded.push_back(std::move(f));
  }
  return folded;
}

MlpTrainingResult train_mlp(ConstRef<MatX> train_x, ConstRef<MatX> train_y, ConstRef<MatX> valid_x,
    ConstRef<MatX> valid_y, const MlpTrainingOptions& o) {
  o.validate();
  const auto start = Clock::now();
  const int inputs = static_cast<int>(train_x.rows());
  const int outputs = static_cast<int>(train_y.rows());
  check_set("training", train_x, train_y, inputs, outputs);
  check_set("validation", valid_x, valid_y, inputs, outputs);
  if (inputs < 1 || outputs < 1)
    mlp_training_error("training", "needs ≥ 1 input and output row");

  BatchNormMlp net = make_batch_norm_mlp(inputs, o.hidden_widths, outputs, o.batch_norm, o.seed);
  net.batch_norm_epsilon = o.batch_norm_epsilon;
  net.activation = o.activation;
  const Eigen::Index n = train_x.cols();
  const Eigen::Index batch = std::min<Eigen::Index>(o.batch_size, n);
  if (batch < 2)
    mlp_training_error("training", "needs ≥ 2 samples, got " + to_text(n));
  const Eigen::Index batches = n / batch; // the remainder (< batch) sits out this epoch
  const std::size_t num_layers = net.layers.size();

  std::vector<LayerWork> work;
  for (const auto& l : net.layers)
    work.emplace_back(l, batch);
  MatX x_batch(inputs, batch), y_batch(outputs, batch);
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(o.seed ^ 0x9e3779b97f4a7c15ULL);

  MlpTrainingResult result { net, {} };
  EarlyStopping stopping { mean_squared_error(net, valid_x, valid_y) };
  double learning_rate = o.learning_rate;
  long step_count = 0;
  const double inv_b = 1.0 / double(batch);
  const double m = o.batch_norm_momentum;

  for (int epoch = 1; epoch <= o.max_epochs; ++epoch) {
    shuffle_in_place(order, rng);
    for (Eigen::Index bi = 0; bi < batches; ++bi) {
      for (Eigen::Index j = 0; j < batch; ++j) {
        const Eigen::Index s = order[static_cast<std::size_t>(bi * batch + j)];
        x_batch.col(j) = train_x.col(s);
        y_batch.col(j) = train_y.col(s);
      }
      // Forward (training mode).
      for (std::size_t k = 0; k < num_layers; ++k) {
        auto& l = net.layers[k];
        auto& w = work[k];
        const MatX& a = k == 0 ? x_batch : work[k - 1].activation;
        w.z.noalias() = l.weight * a;
        w.z.colwise() += l.bias;
        if (k + 1 == num_layers)
          break;
        if (l.has_batch_norm()) {
          const VecX mean = w.z.rowwise().mean();
          w.z_hat = w.z.colwise() - mean;
          const VecX var = w.z_hat.rowwise().squaredNorm() * inv_b;
          w.inv_std = (var.array() + o.batch_norm_epsilon).rsqrt();
          w.z_hat = w.z_hat.array().colwise() * w.inv_std.array();
          // PyTorch's convention: the running variance is the unbiased batch variance.
          l.running_mean = (1 - m) * l.running_mean + m * mean;
          l.running_var = (1 - m) * l.running_var + (m * double(batch) / double(batch - 1)) * var;
          w.z = (w.z_hat.array().colwise() * l.gamma.array()).colwise() + l.beta.array();
        }
        for (Eigen::Index i = 0; i < w.z.size(); ++i) {
          const material::ActivationValues f
              = material::activation_values(o.activation, w.z.data()[i]);
          w.activation.data()[i] = f.f;
          w.slope.data()[i] = f.d1;
        }
      }
      // Backward: g = ∂(mean squared error)/∂(network output), then through the layers; each
      // layer's g lives in its own buffer (out × B), so nothing is allocated per batch.
      work.back().grad = (work.back().z - y_batch) * (2.0 / double(y_batch.size()));
      for (std::size_t k = num_layers; k-- > 0;) {
        auto& l = net.layers[k];
        auto& w = work[k];
        MatX& g = w.grad;
        if (k + 1 < num_layers) {
          g.array() *= w.slope.array(); // ∂L/∂y, y the batch-norm output
          if (l.has_batch_norm()) {
            w.d_gamma = g.cwiseProduct(w.z_hat).rowwise().sum();
            w.d_beta = g.rowwise().sum();
            // ∂L/∂z = γ/σ_B ⊙ (g − mean(g) − ẑ ⊙ mean(g ⊙ ẑ)) (batch means along each row).
            const VecX mean_g = w.d_beta * inv_b;
            const VecX mean_gz = w.d_gamma * inv_b;
            g = (g.array().colwise() - mean_g.array())
                - w.z_hat.array().colwise() * mean_gz.array();
            g = g.array().colwise() * (l.gamma.array() * w.inv_std.array());
          }
        }
        const MatX& a = k == 0 ? x_batch : work[k - 1].activation;
        w.d_weight.noalias() = g * a.transpose();
        w.d_bias = g.rowwise().sum();
        if (k > 0)
          work[k - 1].grad.noalias() = l.weight.transpose() * g;
      }
      // Adam with bias-corrected moments.
      ++step_count;
      const double step = adam_step(o, learning_rate, step_count);
      for (std::size_t k = 0; k < num_layers; ++k) {
        auto& l = net.layers[k];
        auto& w = work[k];
        adam_update(l.weight, w.d_weight, w.weight, o, step);
        if (l.has_batch_norm()) {
          // The bias is redundant before batch norm (its gradient is exactly zero): keep b = 0.
          adam_update(l.gamma, w.d_gamma, w.gamma, o, step);
          adam_update(l.beta, w.d_beta, w.beta, o, step);
        } else {
          adam_update(l.bias, w.d_bias, w.bias, o, step);
        }
      }
    }
    const double loss = mean_squared_error(net, valid_x, valid_y);
    if (!std::isfinite(loss)) {
      mlp_training_error("learning_rate",
          "training diverged at epoch " + to_text(epoch) + " (validation loss " + to_text(loss)
              + "); lower the learning rate");
    }
    result.report.validation_history.push_back(loss);
    result.report.epochs = epoch;
    bool stop = false;
    if (stopping.update(loss, o, learning_rate, stop)) {
      result.network = net;
      result.report.best_epoch = epoch;
    }
    if (stop) {
      result.report.stopped_early = epoch < o.max_epochs;
      break;
    }
  }
  result.report.validation_loss = stopping.best;
  result.report.training_loss = mean_squared_error(result.network, train_x, train_y);
  result.report.seconds = seconds_since(start);
  return result;
}

} // namespace elastolearn::learn
