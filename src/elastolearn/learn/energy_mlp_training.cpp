#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/energy_mlp_training.hpp>

#include <numeric>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors energy_mlp_training_error("mlp_training");

/// Forward buffers of one layer over a batch (B columns): pre-activation Z, f(Z), f'(Z), f''(Z),
/// and per input c the pre-activation tangent U_c = ∂Z/∂x_c and the activation tangent
/// T_c = f'(Z) ⊙ U_c. The output layer uses Z and T only (T_c = its input gradient).
struct Forward {
  MatX z, a, d1, d2;
  std::vector<MatX> u, t;
};

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

/// D_jᵀ ∇g for the columns of a forward pass (m × B).
MatX stress_of(const std::vector<Forward>& f, ConstRef<MatX> maps, int d, int m) {
  const Forward& out = f.back();
  MatX s = MatX::Zero(m, maps.cols());
  for (int i = 0; i < m; ++i)
    for (int c = 0; c < d; ++c)
      s.row(i) += maps.row(c + d * i).cwiseProduct(out.t[std::size_t(c)].row(0));
  return s;
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

double loss_of(const BatchNormMlp& net, const GradientSamples& s) {
  return (network_stress(net, s) - s.targets).squaredNorm() / double(s.targets.size());
}

} // namespace

MatX network_stress(const BatchNormMlp& net, const GradientSamples& s) {
  std::vector<Forward> f(net.layers.size());
  forward(net, s.inputs, f);
  return stress_of(f, s.maps, net.inputs(), static_cast<int>(s.targets.rows()));
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

  std::vector<Forward> f(layers);
  std::vector<AdamMoments> adam_w, adam_b;
  for (const auto& l : net.layers) {
    adam_w.emplace_back(l.weight);
    adam_b.emplace_back(MatX(l.bias));
  }
  std::vector<MatX> grad_w(layers), grad_b(layers);
  MatX x(d, batch), maps(d * m, batch), t(m, batch);
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(o.seed ^ 0x9e3779b97f4a7c15ULL);

  MlpTrainingResult result { net, {} };
  EarlyStopping stopping { loss_of(net, valid) };
  double learning_rate = o.learning_rate;
  long steps = 0;
  // Adjoints: of each layer's activation (Ā) and activation tangents (T̄_c), per layer.
  std::vector<MatX> a_bar(layers);
  std::vector<std::vector<MatX>> t_bar(layers, std::vector<MatX>(std::size_t(d)));
  for (int epoch = 1; epoch <= o.max_epochs; ++epoch) {
    shuffle_in_place(order, rng);
    for (Eigen::Index bi = 0; bi < batches; ++bi) {
      for (Eigen::Index j = 0; j < batch; ++j) {
        const Eigen::Index s = order[static_cast<std::size_t>(bi * batch + j)];
        x.col(j) = train.inputs.col(s);
        maps.col(j) = train.maps.col(s);
        t.col(j) = train.targets.col(s);
      }
      forward(net, x, f);
      const MatX residual = stress_of(f, maps, d, m) - t;
      // Ḡ_c = ∂L/∂(∂g/∂x_c) per sample: (2/(m·B)) Σ_i D(c, i) r_i.
      const double scale = 2.0 / double(m * batch);
      const std::size_t K = layers - 1;
      auto& last = net.layers[K];
      grad_w[K] = MatX::Zero(1, last.weight.cols());
      grad_b[K] = MatX::Zero(1, 1);
      for (int c = 0; c < d; ++c) {
        Eigen::RowVectorXd g_bar = Eigen::RowVectorXd::Zero(batch);
        for (int i = 0; i < m; ++i)
          g_bar += scale * maps.row(c + d * i).cwiseProduct(residual.row(i));
        // ∂g/∂x_c = w_K T_{K−1,c} (or w_K e_c without hidden layers).
        if (K > 0) {
          grad_w[K].noalias() += g_bar * f[K - 1].t[std::size_t(c)].transpose();
          t_bar[K - 1][std::size_t(c)].noalias() = last.weight.transpose() * g_bar;
        } else {
          grad_w[K](0, c) += g_bar.sum();
        }
      }
      if (K > 0)
        a_bar[K - 1] = MatX::Zero(last.weight.cols(), batch); // g's value is not in the loss
      for (std::size_t k = K; k-- > 0;) {
        const auto& l = net.layers[k];
        Forward& w = f[k];
        // Z̄ = f' ⊙ Ā + f'' ⊙ Σ_c T̄_c ⊙ U_c;  Ū_c = f' ⊙ T̄_c.
        MatX z_bar = w.d1.cwiseProduct(a_bar[k]);
        for (int c = 0; c < d; ++c)
          z_bar += w.d2.cwiseProduct(t_bar[k][std::size_t(c)].cwiseProduct(w.u[std::size_t(c)]));
        grad_b[k] = z_bar.rowwise().sum();
        if (k == 0)
          grad_w[k].noalias() = z_bar * x.transpose();
        else
          grad_w[k].noalias() = z_bar * f[k - 1].a.transpose();
        for (int c = 0; c < d; ++c) {
          const MatX u_bar = w.d1.cwiseProduct(t_bar[k][std::size_t(c)]);
          if (k == 0) {
            grad_w[k].col(c) += u_bar.rowwise().sum(); // T_{−1,c} = e_c
          } else {
            grad_w[k].noalias() += u_bar * f[k - 1].t[std::size_t(c)].transpose();
            t_bar[k - 1][std::size_t(c)].noalias() = l.weight.transpose() * u_bar;
          }
        }
        if (k > 0)
          a_bar[k - 1].noalias() = l.weight.transpose() * z_bar;
      }
      const double step = adam_step(o, learning_rate, ++steps);
      for (std::size_t k = 0; k < layers; ++k) {
        adam_update(net.layers[k].weight, grad_w[k], adam_w[k], o, step);
        if (k + 1 < layers)
          adam_update(net.layers[k].bias, grad_b[k], adam_b[k], o, step);
      }
    }
    const double loss = loss_of(net, valid);
    if (!std::isfinite(loss)) {
      energy_mlp_training_error("learning_rate",
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
  result.report.training_loss = loss_of(result.network, train);
  result.report.seconds = seconds_since(start);
  return result;
}

} // namespace elastolearn::learn
