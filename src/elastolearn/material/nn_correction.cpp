#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/nn_correction.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace elastolearn::material {

namespace {

constexpr FieldErrors nn_correction_error("nn_correction");

std::string layer_field(std::size_t k, const char* member) {
  return "layers[" + std::to_string(k) + "]." + member;
}

template <typename Derived>
void check_scale(const char* field, const Eigen::MatrixBase<Derived>& scale) {
  for (Eigen::Index i = 0; i < scale.size(); ++i) {
    if (!std::isfinite(scale[i]) || scale[i] <= 0)
      nn_correction_error(field,
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

using Lanes = Eigen::Array4d;

/// f(z) and f'(z) of four lanes at once: the exponentials run as packed instructions (Eigen's
/// vectorised exp), the rest branch-free. The same values as activation_values up to rounding.
void activate(Activation a, const Lanes& z, Lanes& f, Lanes& d1) {
  switch (a) {
  case Activation::Elu: {
    const Lanes e = z.min(0.0).exp(); // 1 for z > 0: ELU' and ELU − max(z, 0) + 1 at once
    f = z.max(0.0) + (e - 1.0);
    d1 = e;
    return;
  }
  case Activation::Relu:
    f = z.max(0.0);
    d1 = (z > 0).cast<double>();
    return;
  case Activation::Sigmoid: {
    const Lanes s = 1.0 / (1.0 + (-z).exp());
    f = s;
    d1 = s * (1.0 - s);
    return;
  }
  case Activation::Softplus: {
    const Lanes e = (-z.abs()).exp();
    f = z.max(0.0) + e.log1p();
    d1 = 1.0 / (1.0 + (-z).exp());
    return;
  }
  case Activation::Tanh: {
    f = z.tanh();
    d1 = 1.0 - f * f;
    return;
  }
  case Activation::Squareplus: {
    const Lanes q = (z * z + 4.0).sqrt();
    f = 0.5 * (z + q);
    d1 = 0.5 * (1.0 + z / q);
    return;
  }
  }
}

/// f, f', f'' of n units; the switch is outside the loops, so the algebraic activations
/// (squareplus, ReLU) run as packed instructions.
void activate(Activation a, int n, const double* z, double* f, double* d1, double* d2) {
  switch (a) {
  case Activation::Squareplus:
    for (int r = 0; r < n; ++r) {
      const double q = std::sqrt(z[r] * z[r] + 4), inv = 1 / q;
      f[r] = 0.5 * (z[r] + q);
      d1[r] = 0.5 * (1 + z[r] * inv);
      d2[r] = 2 * inv * inv * inv;
    }
    return;
  default:
    for (int r = 0; r < n; ++r) {
      const ActivationValues v = activation_values(a, z[r]);
      f[r] = v.f;
      d1[r] = v.d1;
      d2[r] = v.d2;
    }
  }
}

/// f and f' of a fixed-size block (the stress network's), elementwise: ELU and squareplus as
/// packed array expressions, the others through activation_values.
template <typename Z, typename F> void activate_block(Activation a, const Z& z, F& f, F& d1) {
  switch (a) {
  case Activation::Elu: {
    const F e = z.array().min(0.0).exp().matrix();
    f = (z.array().max(0.0) + (e.array() - 1.0)).matrix();
    d1 = e;
    return;
  }
  case Activation::Squareplus: {
    const auto q = (z.array() * z.array() + 4.0).sqrt().eval();
    const auto inv = q.inverse().eval();
    f = (0.5 * (z.array() + q)).matrix();
    d1 = (0.5 * (1.0 + z.array() * inv)).matrix();
    return;
  }
  default:
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      const ActivationValues v = activation_values(a, z.data()[i]);
      f.data()[i] = v.f;
      d1.data()[i] = v.d1;
    }
  }
}

/// f, f', f'' of a fixed-size block for the energy network's hidden layers, with the value f
/// only if `f` is non-null (the last hidden layer's values are not needed: the network's value
/// is not). Squareplus and ELU as packed array expressions, the others through
/// activation_values.
template <int W>
[[gnu::always_inline]] inline void activate_energy_block(Activation a,
    const Eigen::Matrix<double, W, 1>& z, Eigen::Matrix<double, W, 1>* f,
    Eigen::Matrix<double, W, 1>& d1, Eigen::Matrix<double, W, 1>& d2) {
  switch (a) {
  case Activation::Squareplus: {
    const Eigen::Array<double, W, 1> q = (z.array() * z.array() + 4.0).sqrt(), inv = q.inverse();
    if (f)
      *f = (0.5 * (z.array() + q)).matrix();
    d1 = (0.5 * (1.0 + z.array() * inv)).matrix();
    d2 = (2.0 * inv * inv * inv).matrix();
    return;
  }
  case Activation::Elu: {
    const Eigen::Array<double, W, 1> e = z.array().min(0.0).exp();
    if (f)
      *f = (z.array().max(0.0) + (e - 1.0)).matrix();
    d1 = e.matrix();
    d2 = (z.array() > 0).select(0.0, e).matrix();
    return;
  }
  default:
    for (int i = 0; i < W; ++i) {
      const ActivationValues v = activation_values(a, z[i]);
      if (f)
        (*f)[i] = v.f;
      d1[i] = v.d1;
      d2[i] = v.d2;
    }
  }
}

/// The energy network with two hidden layers of width W (the common architectures;
/// NnCorrection::energy_network_gradient's loops serve the others): ∇_x g and, if `hessian_x` is
/// non-null, ∇²_x g, with the identity of NnCorrection::energy_correction. `k` is the layout
/// NnCorrection::m_energy_kernel holds: W₁ (W × 3), b₁, W₂ (W × W), W₂ᵀ, b₂, w₃, matrices
/// column-major, so that every product below is a sum of columns scaled by one number: W-long
/// packed operations, no horizontal sums but the final dot products.
template <int W>
Vec3 energy_two_layers(const double* k, Activation act, const Vec3& x, Mat3* hessian_x) {
  using VecW = Eigen::Matrix<double, W, 1>;
  using MatW3 = Eigen::Matrix<double, W, 3>;
  using MatWW = Eigen::Matrix<double, W, W>;
  const Eigen::Map<const MatW3> W1(k);
  const Eigen::Map<const VecW> b1(k + 3 * W);
  const Eigen::Map<const MatWW> W2(k + 4 * W);
  const Eigen::Map<const MatWW> W2t(k + 4 * W + W * W);
  const Eigen::Map<const VecW> b2(k + 4 * W + 2 * W * W);
  const Eigen::Map<const VecW> w3(k + 5 * W + 2 * W * W);
  // Forward: z₁ = W₁ x + b₁, a₁ = f(z₁), z₂ = W₂ a₁ + b₂ (the value g = w₃ᵀ f(z₂) + b₃ is not
  // needed).
  const VecW z1 = b1 + W1.col(0) * x[0] + W1.col(1) * x[1] + W1.col(2) * x[2];
  VecW a1, s1, c1, s2, c2;
  activate_energy_block<W>(act, z1, &a1, s1, c1);
  VecW z2 = b2;
  for (int c = 0; c < W; ++c)
    z2 += W2.col(c) * a1[c];
  activate_energy_block<W>(act, z2, nullptr, s2, c2);
  // Reverse: t₂ = ∂g/∂z₂, d₁ = ∂g/∂a₁ = W₂ᵀ t₂, t₁ = ∂g/∂z₁; ∇_x g = W₁ᵀ t₁.
  const VecW t2 = w3.cwiseProduct(s2);
  VecW d1 = W2t.col(0) * t2[0];
  for (int r = 1; r < W; ++r)
    d1 += W2t.col(r) * t2[r];
  const VecW t1 = d1.cwiseProduct(s1);
  if (hessian_x) {
    // J₁ = W₁, J₂ = ∂z₂/∂x = W₂ diag(f'(z₁)) W₁; ∇²g = J₁ᵀ diag(d₁ ⊙ f''₁) J₁ + J₂ᵀ diag(w₃ ⊙
    // f''₂) J₂, its upper triangle then mirrored (symmetric bit for bit).
    MatW3 J2;
    for (int j = 0; j < 3; ++j) {
      const VecW sw = s1.cwiseProduct(W1.col(j));
      VecW col = W2.col(0) * sw[0];
      for (int c = 1; c < W; ++c)
        col += W2.col(c) * sw[c];
      J2.col(j) = col;
    }
    const VecW k1 = d1.cwiseProduct(c1), k2 = w3.cwiseProduct(c2);
    Mat3& h = *hessian_x;
    for (int i = 0; i < 3; ++i) {
      const VecW u1 = k1.cwiseProduct(W1.col(i)), u2 = k2.cwiseProduct(J2.col(i));
      for (int j = i; j < 3; ++j) {
        h(i, j) = (u1.cwiseProduct(W1.col(j)) + u2.cwiseProduct(J2.col(j))).sum();
        h(j, i) = h(i, j);
      }
    }
  }
  return { W1.col(0).dot(t1), W1.col(1).dot(t1), W1.col(2).dot(t1) };
}

/// The stress network with two hidden layers of width W for four input columns at once (the
/// three directions and an idle one), in fixed-size Eigen: g per column and, if d_x is non-null,
/// ∂g/∂x (6 × 4), by reverse mode.
template <int W>
Eigen::Array4d stress_two_layers(const double* flat,
    const std::array<int, NnCorrection::max_hidden_layers + 2>& offset, Activation act,
    const Eigen::Matrix<double, 6, 4>& x, Eigen::Matrix<double, 6, 4>* d_x) {
  using MatW6 = Eigen::Matrix<double, W, 6, Eigen::RowMajor>;
  using MatWW = Eigen::Matrix<double, W, W, Eigen::RowMajor>;
  using VecW = Eigen::Matrix<double, W, 1>;
  using BlockW = Eigen::Matrix<double, W, 4>;
  const Eigen::Map<const MatW6> W1(flat + offset[0]);
  const Eigen::Map<const VecW> b1(flat + offset[0] + 6 * W);
  const Eigen::Map<const MatWW> W2(flat + offset[1]);
  const Eigen::Map<const VecW> b2(flat + offset[1] + W * W);
  const Eigen::Map<const VecW> w3(flat + offset[2]);
  const double b3 = flat[offset[2] + W];
  BlockW a1, s1, a2, s2;
  const BlockW z1 = (W1 * x).colwise() + b1;
  activate_block(act, z1, a1, s1);
  const BlockW z2 = (W2 * a1).colwise() + b2;
  activate_block(act, z2, a2, s2);
  if (d_x) {
    const BlockW t2 = s2.array().colwise() * w3.array();
    const BlockW t1 = (W2.transpose() * t2).cwiseProduct(s1);
    d_x->noalias() = W1.transpose() * t1;
  }
  return ((w3.transpose() * a2).array() + b3).transpose();
}

} // namespace

std::string to_string(NnKind kind) {
  return kind == NnKind::Stress ? "stress" : "energy";
}

NnInput nn_input(const Vec3& s, const Vec3& f, int k) {
  const auto [a, b] = others(k);
  const double ds = s[a] - s[b], df = f[a] - f[b];
  NnInput x;
  x << s[k], s[a] + s[b], 0.5 * ds * ds, f[k], f[a] + f[b], ds * df;
  return x;
}

Vec3 power_sums(const Vec3& stretches) {
  const Vec3 e = stretches - Vec3::Ones();
  const Vec3 e2 = e.cwiseProduct(e);
  return { e.sum(), e2.sum(), e2.dot(e) };
}

namespace {

/// x = energy_input of p, ∂x/∂p and, per input c, the nonzero second derivatives: ∂²q/∂p₂²,
/// ∂²x₃/∂p₂² and ∂²x₃/∂p₂∂p₃ (x₁ = p₁ is linear, x₃ is linear in p₃).
struct EnergyInput {
  Vec3 x;
  Mat3 d_p;
  double q_22, x3_22, x3_23;
};

EnergyInput energy_input_of(const Vec3& p) {
  constexpr double eps2 = energy_input_epsilon * energy_input_epsilon;
  const double q2 = p[1] + eps2, q = std::sqrt(q2), inv_q2 = 1 / q2;
  EnergyInput in;
  in.x = Vec3(p[0], q, p[2] * inv_q2);
  in.d_p << 1, 0, 0, 0, 0.5 / q, 0, 0, -p[2] * inv_q2 * inv_q2, inv_q2;
  in.q_22 = -0.25 / (q * q2);
  in.x3_22 = 2 * p[2] * inv_q2 * inv_q2 * inv_q2;
  in.x3_23 = -inv_q2 * inv_q2;
  return in;
}

} // namespace

Vec3 energy_input(const Vec3& stretches, Mat3* d_p) {
  const EnergyInput in = energy_input_of(power_sums(stretches));
  if (d_p)
    *d_p = in.d_p;
  return in.x;
}

NnCorrection::NnCorrection(Parameters p)
    : m_p(std::move(p)) {
  const int inputs = num_inputs();
  if (m_p.input_mean.size() != inputs)
    nn_correction_error("input_mean",
        "has " + std::to_string(m_p.input_mean.size()) + " entries, expected "
            + std::to_string(inputs) + " (the " + to_string(m_p.kind) + " network's inputs)");
  if (m_p.input_scale.size() != inputs)
    nn_correction_error("input_scale",
        "has " + std::to_string(m_p.input_scale.size()) + " entries, expected "
            + std::to_string(inputs) + " (the " + to_string(m_p.kind) + " network's inputs)");
  if (!m_p.input_mean.allFinite())
    nn_correction_error("input_mean", "contains a non-finite value");
  if (!std::isfinite(m_p.output_mean))
    nn_correction_error("output_mean", "is not finite");
  check_scale("input_scale", m_p.input_scale);
  check_scale("output_scale", Eigen::Matrix<double, 1, 1>(m_p.output_scale));
  if (!m_p.polynomial.allFinite())
    nn_correction_error("polynomial", "contains a non-finite value");
  if (m_p.kind == NnKind::Stress && !m_p.polynomial.isZero(0))
    nn_correction_error(
        "polynomial", "is only for an energy network; a stress network's must be zero");
  m_p.trusted.validate("nn_correction.trusted_stretches");
  if (m_p.kind == NnKind::Stress && m_p.trusted.bounded())
    nn_correction_error(
        "trusted_stretches", "is only for an energy network (a stress network has no energy)");
  if (m_p.layers.empty())
    nn_correction_error("layers",
        "is empty; at least the output layer (1 × " + std::to_string(inputs) + ") is required");
  if (m_p.layers.size() > std::size_t(k_max_hidden) + 1) {
    nn_correction_error("layers",
        "has " + std::to_string(m_p.layers.size() - 1) + " hidden layers, at most "
            + std::to_string(k_max_hidden) + " are supported");
  }
  Eigen::Index in = inputs;
  for (std::size_t k = 0; k < m_p.layers.size(); ++k) {
    const Layer& l = m_p.layers[k];
    const bool last = k + 1 == m_p.layers.size();
    if (l.weight.cols() != in) {
      nn_correction_error(layer_field(k, "weight"),
          "has " + std::to_string(l.weight.cols()) + " columns, expected " + std::to_string(in)
              + (k == 0 ? " (the network's inputs)" : " (the previous layer's outputs)"));
    }
    if (last && l.weight.rows() != 1) {
      nn_correction_error(layer_field(k, "weight"),
          "is the output layer and has " + std::to_string(l.weight.rows())
              + " rows, expected 1 (one scalar network)");
    }
    if (!last && (l.weight.rows() < 1 || l.weight.rows() > k_max)) {
      nn_correction_error(layer_field(k, "weight"),
          "has " + std::to_string(l.weight.rows()) + " rows, expected a hidden width in 1.."
              + std::to_string(k_max));
    }
    if (l.bias.size() != l.weight.rows()) {
      nn_correction_error(layer_field(k, "bias"),
          "has " + std::to_string(l.bias.size()) + " entries, expected "
              + std::to_string(l.weight.rows()));
    }
    if (!l.weight.allFinite())
      nn_correction_error(layer_field(k, "weight"), "contains a non-finite value");
    if (!l.bias.allFinite())
      nn_correction_error(layer_field(k, "bias"), "contains a non-finite value");
    in = l.weight.rows();
  }
  if (m_p.damping && m_p.damping->has_elastic_part())
    nn_correction_error(
        "damping", "must carry only a damping correction (its elastic part must be zero)");

  // Fold the standardisation: L₁((x − μ) ⊘ s) = (W₁ diag(1/s)) x + (b₁ − W₁ (μ ⊘ s)), and
  // μ_y + s_y L_K(a) = (s_y W_K) a + (s_y b_K + μ_y).
  m_layers = static_cast<int>(m_p.layers.size());
  std::size_t size = 0;
  for (const Layer& l : m_p.layers)
    size += static_cast<std::size_t>(l.weight.size() + l.bias.size());
  m_flat.resize(size);
  std::size_t at = 0;
  for (int k = 0; k < m_layers; ++k) {
    MatX W = m_p.layers[std::size_t(k)].weight;
    VecX b = m_p.layers[std::size_t(k)].bias;
    if (k == 0) {
      b -= W * m_p.input_mean.cwiseQuotient(m_p.input_scale);
      W = W * m_p.input_scale.cwiseInverse().asDiagonal();
    }
    if (k + 1 == m_layers) {
      W *= m_p.output_scale;
      b = m_p.output_scale * b + VecX::Constant(1, m_p.output_mean);
    }
    m_offset[std::size_t(k)] = static_cast<int>(at);
    m_width[std::size_t(k)] = static_cast<int>(W.cols());
    for (Eigen::Index r = 0; r < W.rows(); ++r)
      for (Eigen::Index c = 0; c < W.cols(); ++c)
        m_flat[at++] = W(r, c);
    for (Eigen::Index r = 0; r < b.size(); ++r)
      m_flat[at++] = b[r];
  }
  m_width[std::size_t(m_layers)] = 1;
  // Two hidden layers of one common width run the fixed-size kernels.
  if (m_layers == 3 && m_width[1] == m_width[2] && (m_width[1] == 6 || m_width[1] == 8))
    m_fixed_width = m_width[1];
  if (m_fixed_width > 0 && m_p.kind == NnKind::Energy) {
    // energy_two_layers' layout: W₁ (W × 3), b₁, W₂ (W × W), W₂ᵀ, b₂, w₃, column-major.
    const int w = m_fixed_width;
    const double* W1 = m_flat.data() + m_offset[0];
    const double* W2 = m_flat.data() + m_offset[1];
    const double* w3 = m_flat.data() + m_offset[2];
    m_energy_kernel.clear();
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < w; ++r)
        m_energy_kernel.push_back(W1[r * 3 + c]);
    m_energy_kernel.insert(m_energy_kernel.end(), W1 + 3 * w, W1 + 4 * w);
    for (int c = 0; c < w; ++c)
      for (int r = 0; r < w; ++r)
        m_energy_kernel.push_back(W2[r * w + c]);
    m_energy_kernel.insert(m_energy_kernel.end(), W2, W2 + w * w);
    m_energy_kernel.insert(m_energy_kernel.end(), W2 + w * w, W2 + w * w + w);
    m_energy_kernel.insert(m_energy_kernel.end(), w3, w3 + w);
  }
  if (m_p.kind == NnKind::Energy)
    m_ends
        = clamp_ends(m_p.trusted, [&](const Vec3& s, Mat3* h) { return energy_correction(s, h); });
}

Lanes NnCorrection::stress_lanes(const Lanes* x, Lanes* d_x) const {
  // Stack buffers only (no allocation, nothing shared between threads); every entry read is
  // written first. Forward pass: activations a; for the gradient, f'(z) of every hidden unit
  // (layer k at slope[k·k_max ...]). Reverse pass: δ = ∂g/∂(layer input), one vector-matrix
  // product per layer (a scalar output makes reverse mode ~6× cheaper than forward mode here).
  std::array<Lanes, k_max> a, z;
  std::array<Lanes, k_max * k_max_hidden> slope;
  const int hidden = m_layers - 1;
  int width = 6;
  const Lanes* in = x;
  for (int k = 0; k < hidden; ++k) {
    const double* W = m_flat.data() + m_offset[std::size_t(k)];
    const int out = m_width[std::size_t(k) + 1];
    const double* b = W + out * width;
    for (int r = 0; r < out; ++r) {
      Lanes acc = Lanes::Constant(b[r]);
      for (int c = 0; c < width; ++c)
        acc += W[r * width + c] * in[c];
      z[std::size_t(r)] = acc;
    }
    for (int r = 0; r < out; ++r)
      activate(
          m_p.activation, z[std::size_t(r)], a[std::size_t(r)], slope[std::size_t(k * k_max + r)]);
    width = out;
    in = a.data();
  }
  const double* w_out = m_flat.data() + m_offset[std::size_t(hidden)];
  Lanes y = Lanes::Constant(w_out[width]);
  for (int c = 0; c < width; ++c)
    y += w_out[c] * in[c];
  if (d_x) {
    std::array<Lanes, k_max> delta, prev;
    for (int c = 0; c < width; ++c)
      delta[std::size_t(c)] = Lanes::Constant(w_out[c]);
    for (int k = hidden; k-- > 0;) {
      const double* W = m_flat.data() + m_offset[std::size_t(k)];
      const int out = m_width[std::size_t(k) + 1], cols = m_width[std::size_t(k)];
      Lanes* target = k == 0 ? d_x : prev.data();
      for (int c = 0; c < cols; ++c)
        target[c] = Lanes::Zero();
      for (int r = 0; r < out; ++r) {
        const Lanes dz = delta[std::size_t(r)] * slope[std::size_t(k * k_max + r)];
        for (int c = 0; c < cols; ++c)
          target[c] += W[r * cols + c] * dz;
      }
      if (k > 0)
        std::copy_n(prev.begin(), cols, delta.begin());
    }
    if (hidden == 0)
      for (int c = 0; c < 6; ++c)
        d_x[c] = Lanes::Constant(w_out[c]);
  }
  return y;
}

double NnCorrection::evaluate(const NnInput& x, NnInput* d_input) const {
  if (m_p.kind != NnKind::Stress)
    nn_correction_error(
        "kind", "evaluate() takes a stress network's input; this is an energy network");
  std::array<Lanes, 6> lanes, d;
  for (int i = 0; i < 6; ++i)
    lanes[std::size_t(i)] = Lanes::Constant(x[i]);
  const Lanes y = stress_lanes(lanes.data(), d_input ? d.data() : nullptr);
  if (d_input)
    for (int i = 0; i < 6; ++i)
      (*d_input)[i] = d[std::size_t(i)][0];
  return y[0];
}

Vec3 NnCorrection::stress_correction(
    const Vec3& s, const Vec3& f, Mat3* d_stretches, Mat3* d_rates) const {
  std::array<Lanes, 6> x, g;
  for (int k = 0; k < 3; ++k) {
    const NnInput xk = nn_input(s, f, k);
    for (int i = 0; i < 6; ++i)
      x[std::size_t(i)][k] = xk[i];
  }
  for (Lanes& l : x)
    l[3] = l[0]; // the idle lane repeats direction 0 (finite, unused)
  Lanes y;
  if (m_fixed_width > 0) {
    Eigen::Matrix<double, 6, 4> xm, gm;
    for (int i = 0; i < 6; ++i)
      xm.row(i) = x[std::size_t(i)].transpose();
    Eigen::Matrix<double, 6, 4>* d = d_stretches ? &gm : nullptr;
    y = m_fixed_width == 6 ? stress_two_layers<6>(m_flat.data(), m_offset, m_p.activation, xm, d)
                           : stress_two_layers<8>(m_flat.data(), m_offset, m_p.activation, xm, d);
    if (d_stretches)
      for (int i = 0; i < 6; ++i)
        g[std::size_t(i)] = gm.row(i).transpose();
  } else {
    y = stress_lanes(x.data(), d_stretches ? g.data() : nullptr);
  }
  if (d_stretches) {
    for (int k = 0; k < 3; ++k) {
      // Chain rule through x_k = (σ_k, σ_a + σ_b, ½(σ_a − σ_b)², ḟ_k, ḟ_a + ḟ_b,
      // (σ_a − σ_b)(ḟ_a − ḟ_b)). Direction b is written like a with the differences negated, so
      // that swapping a and b gives the same bits.
      const auto [a, b] = others(k);
      const double ds = s[a] - s[b], df = f[a] - f[b];
      const double g0 = g[0][k], g1 = g[1][k], g2 = g[2][k], g3 = g[3][k], g4 = g[4][k],
                   g5 = g[5][k];
      (*d_stretches)(k, k) = g0;
      (*d_stretches)(k, a) = g1 + g2 * ds + g5 * df;
      (*d_stretches)(k, b) = g1 + g2 * -ds + g5 * -df;
      (*d_rates)(k, k) = g3;
      (*d_rates)(k, a) = g4 + g5 * ds;
      (*d_rates)(k, b) = g4 + g5 * -ds;
    }
  }
  return y.head<3>();
}

Vec3 NnCorrection::energy_correction(const Vec3& s, Mat3* hessian) const {
  // p = energy_input(σ) here. Forward: z_k = W_k a_{k−1} + b_k, a_k = f(z_k), and the
  // pre-activation gradients J_k = ∂z_k/∂p (J_1 = W_1, J_k = W_k diag(f'(z_{k−1})) J_{k−1}).
  // Reverse: δ_k = ∂g/∂a_k, t_k = δ_k ⊙ f'(z_k) = ∂g/∂z_k, δ_{k−1} = W_kᵀ t_k; ∇_p g = W_1ᵀ t_1 and
  // ∇²_p g = Σ_k Σ_r δ_k,r f''(z_k,r) J_k,r J_k,rᵀ. The value g itself is not needed.
  const Vec3 e = s - Vec3::Ones();
  const Vec3 p = power_sums(s);
  const EnergyInput in = energy_input_of(p);
  Mat3 h_x;
  Mat3* want_h = hessian ? &h_x : nullptr;
  Vec3 g_x;
  if (m_fixed_width == 6)
    g_x = energy_two_layers<6>(m_energy_kernel.data(), m_p.activation, in.x, want_h);
  else if (m_fixed_width == 8)
    g_x = energy_two_layers<8>(m_energy_kernel.data(), m_p.activation, in.x, want_h);
  else
    g_x = energy_network_gradient(in.x, want_h);
  // From x to p: ∇_p = Dᵀ ∇_x, ∇²_p = Dᵀ ∇²_x D + Σ_c ∂g/∂x_c ∇²_p x_c with D = ∂x/∂p, whose
  // only entries besides D₀₀ = 1 are D₁₁ = ∂q/∂p₂, D₂₁ = ∂x₃/∂p₂ and D₂₂ = ∂x₃/∂p₃ (written
  // out: the upper triangle, which is all energy_chain reads).
  const double d11 = in.d_p(1, 1), d21 = in.d_p(2, 1), d22 = in.d_p(2, 2);
  const Vec3 grad_p(g_x[0], d11 * g_x[1] + d21 * g_x[2], d22 * g_x[2]);
  Mat3 h_p;
  if (hessian) {
    const Mat3& h = h_x;
    h_p(0, 0) = h(0, 0);
    h_p(0, 1) = d11 * h(0, 1) + d21 * h(0, 2);
    h_p(0, 2) = d22 * h(0, 2);
    h_p(1, 1) = d11 * d11 * h(1, 1) + 2 * d11 * d21 * h(1, 2) + d21 * d21 * h(2, 2)
        + g_x[1] * in.q_22 + g_x[2] * in.x3_22;
    h_p(1, 2) = d22 * (d11 * h(1, 2) + d21 * h(2, 2)) + g_x[2] * in.x3_23;
    h_p(2, 2) = d22 * d22 * h(2, 2);
  }
  return energy_chain(e, p, grad_p, hessian ? &h_p : nullptr, hessian);
}

Vec3 NnCorrection::energy_network_gradient(const Vec3& p, Mat3* hessian_p) const {
  // (p is the network input x = energy_input(σ) here.)
  std::array<double, k_max> a, z, delta, t;
  std::array<double, k_max * k_max_hidden * 3> J; // layer k unit r at J[(k·k_max + r)·3]
  std::array<double, k_max * k_max_hidden> slope, curvature;
  const int hidden = m_layers - 1;
  const bool want_h = hessian_p != nullptr;
  int width = 3;
  const double* in = p.data();
  for (int k = 0; k < hidden; ++k) {
    const double* W = m_flat.data() + m_offset[std::size_t(k)];
    const int out = m_width[std::size_t(k) + 1];
    const double* b = W + out * width;
    for (int r = 0; r < out; ++r) {
      double acc = b[r];
      for (int c = 0; c < width; ++c)
        acc += W[r * width + c] * in[c];
      z[std::size_t(r)] = acc;
    }
    activate(m_p.activation, out, z.data(), a.data(), slope.data() + k * k_max,
        curvature.data() + k * k_max);
    if (want_h) {
      double* Jk = J.data() + std::size_t(k * k_max * 3);
      if (k == 0) {
        for (int r = 0; r < out; ++r)
          for (int c = 0; c < 3; ++c)
            Jk[r * 3 + c] = W[r * 3 + c];
      } else {
        const double* Jp = J.data() + std::size_t((k - 1) * k_max * 3);
        const double* dp = slope.data() + (k - 1) * k_max;
        for (int r = 0; r < out; ++r) {
          double j0 = 0, j1 = 0, j2 = 0;
          for (int c = 0; c < width; ++c) {
            const double w = W[r * width + c] * dp[c];
            j0 += w * Jp[c * 3];
            j1 += w * Jp[c * 3 + 1];
            j2 += w * Jp[c * 3 + 2];
          }
          Jk[r * 3] = j0;
          Jk[r * 3 + 1] = j1;
          Jk[r * 3 + 2] = j2;
        }
      }
    }
    width = out;
    in = a.data();
  }
  // Reverse pass, accumulating the Hessian in p.
  const double* w_out = m_flat.data() + m_offset[std::size_t(hidden)];
  std::copy_n(w_out, width, delta.begin());
  double h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0;
  for (int k = hidden; k-- > 0;) {
    const double* W = m_flat.data() + m_offset[std::size_t(k)];
    const int out = m_width[std::size_t(k) + 1], cols = m_width[std::size_t(k)];
    const double* sk = slope.data() + k * k_max;
    const double* ck = curvature.data() + k * k_max;
    for (int r = 0; r < out; ++r)
      t[std::size_t(r)] = delta[std::size_t(r)] * sk[r];
    if (want_h) {
      const double* Jk = J.data() + std::size_t(k * k_max * 3);
      for (int r = 0; r < out; ++r) {
        const double c = delta[std::size_t(r)] * ck[r];
        const double j0 = Jk[r * 3], j1 = Jk[r * 3 + 1], j2 = Jk[r * 3 + 2];
        h00 += c * j0 * j0;
        h01 += c * j0 * j1;
        h02 += c * j0 * j2;
        h11 += c * j1 * j1;
        h12 += c * j1 * j2;
        h22 += c * j2 * j2;
      }
    }
    for (int c = 0; c < cols; ++c)
      delta[std::size_t(c)] = 0;
    for (int r = 0; r < out; ++r)
      for (int c = 0; c < cols; ++c)
        delta[std::size_t(c)] += W[r * cols + c] * t[std::size_t(r)];
  }
  if (want_h)
    *hessian_p << h00, h01, h02, h01, h11, h12, h02, h12, h22;
  return Vec3(delta[0], delta[1], delta[2]); // W_1ᵀ t_1, or the output layer's weights alone
}

Vec3 NnCorrection::energy_chain(
    const Vec3& e, const Vec3& p, Vec3 grad_p, const Mat3* hessian_p, Mat3* hessian) const {
  // The polynomial cᵀ m(p), m = (p₁, p₁², p₂, p₁³, p₁p₂, p₃).
  const auto& c = m_p.polynomial;
  grad_p[0] += c[0] + 2 * c[1] * p[0] + 3 * c[3] * p[0] * p[0] + c[4] * p[1];
  grad_p[1] += c[2] + c[4] * p[0];
  grad_p[2] += c[5];
  // To σ: ∂p/∂σ_i = (1, 2e_i, 3e_i²); N_i = Σ_j ∂ΔΨ/∂p_j ∂p_j/∂σ_i depends on i through e_i only.
  Vec3 n;
  for (int i = 0; i < 3; ++i)
    n[i] = grad_p[0] + 2 * e[i] * grad_p[1] + 3 * e[i] * e[i] * grad_p[2];
  if (hessian) {
    const Mat3& h = *hessian_p;
    const double h00 = h(0, 0) + 2 * c[1] + 6 * c[3] * p[0], h01 = h(0, 1) + c[4], h02 = h(0, 2),
                 h11 = h(1, 1), h12 = h(1, 2), h22 = h(2, 2);
    // ∇²ΔΨ = Bᵀ H_p B + Σ_j ∂ΔΨ/∂p_j ∇²p_j, B's column i = (1, 2e_i, 3e_i²), ∇²p₂ = 2I,
    // ∇²p₃ = 6 diag(e); written entry by entry from the symmetric H_p, so (i, j) and (j, i)
    // are the same bits.
    for (int i = 0; i < 3; ++i) {
      const double bi0 = 1, bi1 = 2 * e[i], bi2 = 3 * e[i] * e[i];
      const double u0 = h00 * bi0 + h01 * bi1 + h02 * bi2;
      const double u1 = h01 * bi0 + h11 * bi1 + h12 * bi2;
      const double u2 = h02 * bi0 + h12 * bi1 + h22 * bi2;
      for (int j = i; j < 3; ++j) {
        const double v = u0 + u1 * 2 * e[j] + u2 * 3 * e[j] * e[j];
        (*hessian)(i, j) = v;
        (*hessian)(j, i) = v;
      }
      (*hessian)(i, i) += 2 * grad_p[1] + 6 * e[i] * grad_p[2];
    }
  }
  return n;
}

double NnCorrection::elastic_energy(const Vec3& stretches) const {
  if (m_p.kind != NnKind::Energy)
    nn_correction_error("kind", "a stress network has no energy");
  return continued_energy(
      m_p.trusted, m_ends, stretches, [&](const Vec3& s) { return formula_energy(s); },
      [&](const Vec3& s, Mat3* h) { return energy_correction(s, h); });
}

double NnCorrection::formula_energy(const Vec3& stretches) const {
  const Vec3 p = power_sums(stretches), x = energy_input(stretches);
  std::array<double, k_max> a;
  int width = 3;
  const double* in = x.data();
  std::array<double, k_max> next;
  for (int k = 0; k + 1 < m_layers; ++k) {
    const double* W = m_flat.data() + m_offset[std::size_t(k)];
    const int out = m_width[std::size_t(k) + 1];
    for (int r = 0; r < out; ++r) {
      double acc = W[out * width + r];
      for (int c = 0; c < width; ++c)
        acc += W[r * width + c] * in[c];
      next[std::size_t(r)] = activation_values(m_p.activation, acc).f;
    }
    a = next;
    width = out;
    in = a.data();
  }
  const double* w_out = m_flat.data() + m_offset[std::size_t(m_layers - 1)];
  double y = w_out[width];
  for (int c = 0; c < width; ++c)
    y += w_out[c] * in[c];
  const auto& c = m_p.polynomial;
  return y + c[0] * p[0] + c[1] * p[0] * p[0] + c[2] * p[1] + c[3] * p[0] * p[0] * p[0]
      + c[4] * p[0] * p[1] + c[5] * p[2];
}

Vec3 NnCorrection::correction(const Vec3& stretches, const Vec3& stretch_rates) const {
  if (m_p.kind == NnKind::Energy)
    return continued_correction(m_p.trusted, m_ends, stretches, nullptr,
        [&](const Vec3& s, Mat3* h) { return energy_correction(s, h); });
  return stress_correction(stretches, stretch_rates, nullptr, nullptr);
}

Vec3 NnCorrection::correction_with_gradient(
    const Vec3& s, const Vec3& f, Mat3& d_stretches, Mat3& d_stretch_rates) const {
  if (m_p.kind == NnKind::Energy) {
    d_stretch_rates.setZero();
    return continued_correction(m_p.trusted, m_ends, s, &d_stretches,
        [&](const Vec3& c, Mat3* h) { return energy_correction(c, h); });
  }
  return stress_correction(s, f, &d_stretches, &d_stretch_rates);
}

void NnCorrection::correction_gradient(
    const Vec3& s, const Vec3& f, Mat3& d_stretches, Mat3& d_stretch_rates) const {
  correction_with_gradient(s, f, d_stretches, d_stretch_rates);
}

std::unique_ptr<Correction> NnCorrection::clone() const {
  return std::make_unique<NnCorrection>(*this);
}

} // namespace elastolearn::material
