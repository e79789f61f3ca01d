#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/nn_correction.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace elastolearn::material {

namespace {

constexpr FieldErrors fail("nn_correction");

std::string layer_field(std::size_t k, const char* member) {
  return "layers[" + std::to_string(k) + "]." + member;
}

template <typename Derived>
void check_scale(const char* field, const Eigen::MatrixBase<Derived>& scale) {
  for (Eigen::Index i = 0; i < scale.size(); ++i) {
    if (!std::isfinite(scale[i]) || scale[i] <= 0)
      fail(field,
          "entry " + std::to_string(i) + " must be finite and > 0, got " + to_text(scale[i]));
  }
}

constexpr int k_max = NnCorrection::max_width;
constexpr int k_max_hidden = NnCorrection::max_hidden_layers;

/// The other two directions of k, lower index first.
struct Others {
  int a, b;
};
Others others(int k) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  return { std::min(i, j), std::max(i, j) };
}

} // namespace

NnInput nn_input(const Vec3& s, const Vec3& f, int k) {
  const auto [a, b] = others(k);
  const double ds = s[a] - s[b], df = f[a] - f[b];
  NnInput x;
  x << s[k], s[a] + s[b], 0.5 * ds * ds, f[k], f[a] + f[b], ds * df;
  return x;
}

NnCorrection::NnCorrection(Parameters p)
    : m_p(std::move(p)) {
  if (!m_p.input_mean.allFinite())
    fail("input_mean", "contains a non-finite value");
  if (!std::isfinite(m_p.output_mean))
    fail("output_mean", "is not finite");
  check_scale("input_scale", m_p.input_scale);
  check_scale("output_scale", Eigen::Matrix<double, 1, 1>(m_p.output_scale));
  if (m_p.layers.empty())
    fail("layers", "is empty; at least the output layer (1 × 6) is required");
  if (m_p.layers.size() > std::size_t(k_max_hidden) + 1) {
    fail("layers",
        "has " + std::to_string(m_p.layers.size() - 1) + " hidden layers, at most "
            + std::to_string(k_max_hidden) + " are supported");
  }
  Eigen::Index inputs = 6;
  for (std::size_t k = 0; k < m_p.layers.size(); ++k) {
    const Layer& l = m_p.layers[k];
    const bool last = k + 1 == m_p.layers.size();
    if (l.weight.cols() != inputs) {
      fail(layer_field(k, "weight"),
          "has " + std::to_string(l.weight.cols()) + " columns, expected " + std::to_string(inputs)
              + " (the previous layer's outputs)");
    }
    if (last && l.weight.rows() != 1) {
      fail(layer_field(k, "weight"),
          "is the output layer and has " + std::to_string(l.weight.rows())
              + " rows, expected 1 (one network shared by the three principal directions)");
    }
    if (!last && (l.weight.rows() < 1 || l.weight.rows() > k_max)) {
      fail(layer_field(k, "weight"),
          "has " + std::to_string(l.weight.rows()) + " rows, expected a hidden width in 1.."
              + std::to_string(k_max));
    }
    if (l.bias.size() != l.weight.rows()) {
      fail(layer_field(k, "bias"),
          "has " + std::to_string(l.bias.size()) + " entries, expected "
              + std::to_string(l.weight.rows()));
    }
    if (!l.weight.allFinite())
      fail(layer_field(k, "weight"), "contains a non-finite value");
    if (!l.bias.allFinite())
      fail(layer_field(k, "bias"), "contains a non-finite value");
    inputs = l.weight.rows();
  }
  if (m_p.damping && m_p.damping->has_elastic_part())
    fail("damping", "must carry only a damping correction (its elastic part must be zero)");
}

double NnCorrection::evaluate(const NnInput& x, NnInput* d_input) const {
  // Stack buffers only (no allocation, nothing shared between threads); every entry read is
  // written first. Forward pass: activations a; for the gradient, ELU'(z) of every hidden unit
  // (layer k at d[k·k_max ...]). Reverse pass: δ = ∂g/∂(layer input), one vector-matrix product
  // per layer (a scalar output makes reverse mode ~6× cheaper than forward mode here).
  std::array<double, k_max> a, z;
  std::array<double, k_max * k_max_hidden> d;
  const std::size_t num_layers = m_p.layers.size();
  for (int i = 0; i < 6; ++i)
    a[i] = (x[i] - m_p.input_mean[i]) / m_p.input_scale[i];
  int width = 6;
  for (std::size_t k = 0; k + 1 < num_layers; ++k) {
    const MatX& W = m_p.layers[k].weight;
    const VecX& b = m_p.layers[k].bias;
    const int out = static_cast<int>(W.rows());
    for (int r = 0; r < out; ++r) {
      double acc = b[r];
      for (int c = 0; c < width; ++c)
        acc += W(r, c) * a[c];
      z[r] = acc;
    }
    // ELU (α = 1) and its derivative 1 (z > 0) or eᶻ (z ≤ 0).
    double* dk = &d[k * k_max];
    for (int r = 0; r < out; ++r) {
      const double e = z[r] > 0 ? 1.0 : std::exp(z[r]);
      a[r] = z[r] > 0 ? z[r] : e - 1.0;
      dk[r] = e;
    }
    width = out;
  }
  const MatX& w_out = m_p.layers.back().weight; // 1 × width
  double y = m_p.layers.back().bias[0];
  for (int c = 0; c < width; ++c)
    y += w_out(0, c) * a[c];
  if (d_input) {
    std::array<double, k_max> delta, prev;
    for (int c = 0; c < width; ++c)
      delta[c] = w_out(0, c);
    for (std::size_t k = num_layers - 1; k-- > 0;) {
      const MatX& W = m_p.layers[k].weight;
      const int out = static_cast<int>(W.rows()), in = static_cast<int>(W.cols());
      const double* dk = &d[k * k_max];
      for (int c = 0; c < in; ++c)
        prev[c] = 0;
      for (int r = 0; r < out; ++r) {
        const double dz = delta[r] * dk[r];
        for (int c = 0; c < in; ++c)
          prev[c] += W(r, c) * dz;
      }
      for (int c = 0; c < in; ++c)
        delta[c] = prev[c];
    }
    for (int i = 0; i < 6; ++i)
      (*d_input)[i] = m_p.output_scale * delta[i] / m_p.input_scale[i];
  }
  return m_p.output_mean + m_p.output_scale * y;
}

Vec3 NnCorrection::correction(const Vec3& stretches, const Vec3& stretch_rates) const {
  Vec3 n;
  for (int k = 0; k < 3; ++k)
    n[k] = evaluate(nn_input(stretches, stretch_rates, k));
  return n;
}

void NnCorrection::correction_gradient(
    const Vec3& s, const Vec3& f, Mat3& d_stretches, Mat3& d_stretch_rates) const {
  for (int k = 0; k < 3; ++k) {
    NnInput g;
    evaluate(nn_input(s, f, k), &g);
    // Chain rule through x_k = (σ_k, σ_a + σ_b, ½(σ_a − σ_b)², ḟ_k, ḟ_a + ḟ_b, (σ_a − σ_b)(ḟ_a −
    // ḟ_b)). Direction b is written like a with the differences negated, so that swapping a and b
    // gives the same bits.
    const auto [a, b] = others(k);
    const double ds = s[a] - s[b], df = f[a] - f[b];
    d_stretches(k, k) = g[0];
    d_stretches(k, a) = g[1] + g[2] * ds + g[5] * df;
    d_stretches(k, b) = g[1] + g[2] * -ds + g[5] * -df;
    d_stretch_rates(k, k) = g[3];
    d_stretch_rates(k, a) = g[4] + g[5] * ds;
    d_stretch_rates(k, b) = g[4] + g[5] * -ds;
  }
}

std::unique_ptr<Correction> NnCorrection::clone() const {
  return std::make_unique<NnCorrection>(*this);
}

} // namespace elastolearn::material
