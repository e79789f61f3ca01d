#include <elastolearn/core/error.hpp>
#include <elastolearn/material/nn_correction.hpp>

#include <array>
#include <cmath>
#include <sstream>

namespace elastolearn::material {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw InputError("nn_correction." + field, what);
}

std::string layer_field(std::size_t k, const char* member) {
  return "layers[" + std::to_string(k) + "]." + member;
}

/// Stable descending order of three values: order[i] = index of the i-th largest.
std::array<int, 3> descending_order(const Vec3& v) {
  std::array<int, 3> order { 0, 1, 2 };
  for (int i = 1; i < 3; ++i) {
    for (int j = i; j > 0 && v[order[j]] > v[order[j - 1]]; --j)
      std::swap(order[j], order[j - 1]);
  }
  return order;
}

template <typename Derived>
void check_scale(const char* field, const Eigen::MatrixBase<Derived>& scale) {
  for (Eigen::Index i = 0; i < scale.size(); ++i) {
    if (!std::isfinite(scale[i]) || scale[i] <= 0) {
      std::ostringstream s;
      s << "entry " << i << " must be finite and > 0, got " << scale[i];
      fail(field, s.str());
    }
  }
}

constexpr int k_max = NnCorrection::max_width;

} // namespace

NnCorrection::NnCorrection(Parameters p)
    : m_p(std::move(p)) {
  if (!m_p.input_mean.allFinite())
    fail("input_mean", "contains a non-finite value");
  if (!m_p.output_mean.allFinite())
    fail("output_mean", "contains a non-finite value");
  check_scale("input_scale", m_p.input_scale);
  check_scale("output_scale", m_p.output_scale);
  if (m_p.layers.empty())
    fail("layers", "is empty; at least the output layer (3 × 6) is required");
  Eigen::Index inputs = 6;
  for (std::size_t k = 0; k < m_p.layers.size(); ++k) {
    const Layer& l = m_p.layers[k];
    const bool last = k + 1 == m_p.layers.size();
    if (l.weight.cols() != inputs) {
      fail(layer_field(k, "weight"),
          "has " + std::to_string(l.weight.cols()) + " columns, expected "
              + std::to_string(inputs) + " (the previous layer's outputs)");
    }
    if (last && l.weight.rows() != 3) {
      fail(layer_field(k, "weight"),
          "is the output layer and has " + std::to_string(l.weight.rows())
              + " rows, expected 3");
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
}

Vec3 NnCorrection::evaluate_sorted(
    const Vec3& s, const Vec3& f, Eigen::Matrix<double, 3, 6>* jacobian) const {
  // Activations a (width ≤ k_max) and, for the gradient, J = ∂a/∂x (width × 6, row-major) in
  // ping-pong stack buffers: no allocation, nothing shared between threads.
  // (Left uninitialised: every entry read is written first.)
  std::array<double, k_max> a, z;
  std::array<double, k_max * 6> J, Jz;
  const bool gradient = jacobian != nullptr;
  int width = 6;
  for (int i = 0; i < 3; ++i) {
    a[i] = (s[i] - m_p.input_mean[i]) / m_p.input_scale[i];
    a[i + 3] = (f[i] - m_p.input_mean[i + 3]) / m_p.input_scale[i + 3];
  }
  if (gradient) {
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j)
        J[i * 6 + j] = i == j ? 1.0 / m_p.input_scale[i] : 0.0;
    }
  }
  const std::size_t num_layers = m_p.layers.size();
  for (std::size_t k = 0; k < num_layers; ++k) {
    const MatX& W = m_p.layers[k].weight;
    const VecX& b = m_p.layers[k].bias;
    const int out = static_cast<int>(W.rows());
    for (int r = 0; r < out; ++r) {
      double acc = b[r];
      for (int c = 0; c < width; ++c)
        acc += W(r, c) * a[c];
      z[r] = acc;
    }
    if (gradient) {
      for (int r = 0; r < out; ++r) {
        double* row = &Jz[static_cast<std::size_t>(r) * 6];
        for (int j = 0; j < 6; ++j)
          row[j] = 0;
        for (int c = 0; c < width; ++c) {
          const double w = W(r, c);
          const double* in = &J[static_cast<std::size_t>(c) * 6];
          for (int j = 0; j < 6; ++j) // fixed trip count: vectorised
            row[j] += w * in[j];
        }
      }
    }
    width = out;
    if (k + 1 == num_layers)
      break;
    // ELU (α = 1) and its derivative 1 (z > 0) or eᶻ (z ≤ 0).
    for (int r = 0; r < out; ++r) {
      const double e = z[r] > 0 ? 1.0 : std::exp(z[r]);
      a[r] = z[r] > 0 ? z[r] : e - 1.0;
      if (gradient) {
        for (int j = 0; j < 6; ++j)
          J[r * 6 + j] = e * Jz[r * 6 + j];
      }
    }
  }
  Vec3 n;
  for (int i = 0; i < 3; ++i) {
    n[i] = m_p.output_mean[i] + m_p.output_scale[i] * z[i];
    if (gradient) {
      for (int j = 0; j < 6; ++j)
        (*jacobian)(i, j) = m_p.output_scale[i] * Jz[i * 6 + j];
    }
  }
  return n;
}

Vec3 NnCorrection::correction(const Vec3& stretches, const Vec3& stretch_rates) const {
  const std::array<int, 3> p = descending_order(stretches);
  const Vec3 s(stretches[p[0]], stretches[p[1]], stretches[p[2]]);
  const Vec3 f(stretch_rates[p[0]], stretch_rates[p[1]], stretch_rates[p[2]]);
  const Vec3 n_sorted = evaluate_sorted(s, f, nullptr);
  Vec3 n;
  for (int i = 0; i < 3; ++i)
    n[p[i]] = n_sorted[i];
  return n;
}

void NnCorrection::correction_gradient(const Vec3& stretches, const Vec3& stretch_rates,
    Mat3& d_stretches, Mat3& d_stretch_rates) const {
  const std::array<int, 3> p = descending_order(stretches);
  const Vec3 s(stretches[p[0]], stretches[p[1]], stretches[p[2]]);
  const Vec3 f(stretch_rates[p[0]], stretch_rates[p[1]], stretch_rates[p[2]]);
  Eigen::Matrix<double, 3, 6> g;
  evaluate_sorted(s, f, &g);
  // N[p[i]] = N_sorted[i](σ[p[0]], σ[p[1]], σ[p[2]], …): ∂N[p[i]]/∂σ[p[j]] = ∂N_sorted[i]/∂s[j].
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      d_stretches(p[i], p[j]) = g(i, j);
      d_stretch_rates(p[i], p[j]) = g(i, j + 3);
    }
  }
}

std::unique_ptr<Correction> NnCorrection::clone() const {
  return std::make_unique<NnCorrection>(*this);
}

} // namespace elastolearn::material
