#include <elastolearn/core/error.hpp>
#include <elastolearn/material/energy_kernel_copies.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#if defined(__x86_64__) && defined(__GNUC__)
#define ELASTOLEARN_AVX_KERNELS 1
#include <immintrin.h>
#endif

namespace elastolearn::material {

namespace {

/// The Hessian Σ_j w_j ∇²φ_j = (Σ_j w_j/φ_j) I − Σ_j (w_j/φ_j³) d_j d_jᵀ from its sums.
Mat3 kernel_hessian(double diag, double xx, double yy, double zz, double xy, double xz, double yz) {
  return (Mat3() << diag - xx, -xy, -xz, -xy, diag - yy, -yz, -xz, -yz, diag - zz).finished();
}

/// The sum of four lanes in one fixed order, (l₀ + l₂) + (l₁ + l₃), so that both paths round
/// alike.
double lane_sum(const Eigen::Array4d& a) {
  return (a[0] + a[2]) + (a[1] + a[3]);
}

#ifdef ELASTOLEARN_AVX_KERNELS
// Written with intrinsics by hand: Eigen picks its packets at compile time (SSE2 for a portable
// x86-64 build), and this loop's square roots and divisions are the hottest instructions of a
// simulation with a learned correction. Four lanes per instruction instead of two make a whole
// learning run measurably faster (docs/performance.md, "Learning"). Every operation is the
// portable path's, in its order and without FMA, so the two agree bit for bit.

[[gnu::target("avx")]] double lane_sum(__m256d a) {
  const __m128d pairs = _mm_add_pd(_mm256_castpd256_pd128(a), _mm256_extractf128_pd(a, 1));
  return _mm_cvtsd_f64(_mm_add_sd(pairs, _mm_unpackhi_pd(pairs, pairs)));
}

/// sum + (a b) c.
[[gnu::target("avx")]] inline __m256d add_product(__m256d sum, __m256d a, __m256d b, __m256d c) {
  return _mm256_add_pd(sum, _mm256_mul_pd(_mm256_mul_pd(a, b), c));
}

template <bool WithHessian>
[[gnu::target("avx")]] Vec3 gradient_sum_avx(const double* x, const double* y, const double* z,
    const double* w, Eigen::Index n, double eps2, const Vec3& s, Mat3* hessian) {
  const __m256d sx = _mm256_set1_pd(s[0]), sy = _mm256_set1_pd(s[1]), sz = _mm256_set1_pd(s[2]),
                e2 = _mm256_set1_pd(eps2), one = _mm256_set1_pd(1.0);
  __m256d gx = _mm256_setzero_pd(), gy = gx, gz = gx, diag = gx, hxx = gx, hyy = gx, hzz = gx,
          hxy = gx, hxz = gx, hyz = gx;
  for (Eigen::Index j = 0; j < n; j += 4) {
    const __m256d dx = _mm256_sub_pd(sx, _mm256_loadu_pd(x + j)),
                  dy = _mm256_sub_pd(sy, _mm256_loadu_pd(y + j)),
                  dz = _mm256_sub_pd(sz, _mm256_loadu_pd(z + j));
    const __m256d r2
        = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                            _mm256_mul_pd(dz, dz)),
            e2);
    const __m256d inv_phi = _mm256_div_pd(one, _mm256_sqrt_pd(r2));
    const __m256d inv = _mm256_mul_pd(_mm256_loadu_pd(w + j), inv_phi);
    gx = _mm256_add_pd(gx, _mm256_mul_pd(inv, dx));
    gy = _mm256_add_pd(gy, _mm256_mul_pd(inv, dy));
    gz = _mm256_add_pd(gz, _mm256_mul_pd(inv, dz));
    if constexpr (WithHessian) {
      const __m256d inv3 = _mm256_mul_pd(_mm256_mul_pd(inv, inv_phi), inv_phi);
      diag = _mm256_add_pd(diag, inv);
      hxx = add_product(hxx, inv3, dx, dx);
      hyy = add_product(hyy, inv3, dy, dy);
      hzz = add_product(hzz, inv3, dz, dz);
      hxy = add_product(hxy, inv3, dx, dy);
      hxz = add_product(hxz, inv3, dx, dz);
      hyz = add_product(hyz, inv3, dy, dz);
    }
  }
  if constexpr (WithHessian)
    *hessian += kernel_hessian(lane_sum(diag), lane_sum(hxx), lane_sum(hyy), lane_sum(hzz),
        lane_sum(hxy), lane_sum(hxz), lane_sum(hyz));
  return { lane_sum(gx), lane_sum(gy), lane_sum(gz) };
}

/// Whether the CPU and the OS support AVX. This runs among the static initialisers, which may
/// precede libgcc's own CPU detection, hence __builtin_cpu_init first.
bool detect_avx() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx");
}

const bool k_has_avx = detect_avx();
#else
constexpr bool k_has_avx = false;
#endif

} // namespace

EnergyKernelCopies::EnergyKernelCopies(
    ConstRef<MatX> centres, ConstRef<VecX> weights, double epsilon)
    : m_epsilon(epsilon) {
  ELASTOLEARN_CHECK(centres.cols() == 3 && weights.size() == centres.rows(),
      "centres must be m × 3 with m weights");
  const Eigen::Index n = 6 * centres.rows(), padded = (n + 3) / 4 * 4;
  for (auto* a : { &m_x, &m_y, &m_z })
    a->setConstant(padded, 1e3);
  m_w.setZero(padded);
  Eigen::Index j = 0;
  for (Eigen::Index i = 0; i < centres.rows(); ++i)
    for (const auto& pi : kStretchPermutations) {
      // ‖P_π σ − c‖ = ‖σ − P_π⁻¹ c‖: component π_l of the copy is c_l.
      Vec3 copy;
      for (int l = 0; l < 3; ++l)
        copy[pi[l]] = centres(i, l);
      m_x[j] = copy[0];
      m_y[j] = copy[1];
      m_z[j] = copy[2];
      m_w[j++] = weights[i];
    }
}

bool EnergyKernelCopies::uses_avx() {
  return k_has_avx;
}

Vec3 EnergyKernelCopies::gradient_sum(const Vec3& stretches, Mat3* hessian) const {
  const double eps2 = m_epsilon * m_epsilon;
#ifdef ELASTOLEARN_AVX_KERNELS
  if (k_has_avx && eps2 > 0) { // ε = 0 needs the portable path's select
    const auto run = hessian ? gradient_sum_avx<true> : gradient_sum_avx<false>;
    return run(
        m_x.data(), m_y.data(), m_z.data(), m_w.data(), m_w.size(), eps2, stretches, hessian);
  }
#endif
  return gradient_sum_portable(stretches, hessian);
}

Vec3 EnergyKernelCopies::gradient_sum_portable(const Vec3& stretches, Mat3* hessian) const {
  // Σ_j w_j ∇φ_j = Σ_j w_j d_j/φ_j and Σ_j w_j ∇²φ_j = (Σ_j w_j/φ_j) I − Σ_j (w_j/φ_j³) d_j d_jᵀ
  // over the copies j (d_j = σ − copy_j), four copies per packed step.
  using Lanes = Eigen::Array4d;
  const double eps2 = m_epsilon * m_epsilon;
  const bool smoothed = eps2 > 0;
  Lanes gx = Lanes::Zero(), gy = Lanes::Zero(), gz = Lanes::Zero(), diag = Lanes::Zero(),
        hxx = Lanes::Zero(), hyy = Lanes::Zero(), hzz = Lanes::Zero(), hxy = Lanes::Zero(),
        hxz = Lanes::Zero(), hyz = Lanes::Zero();
  for (Eigen::Index j = 0; j < m_w.size(); j += 4) {
    const Lanes dx = stretches[0] - m_x.segment<4>(j), dy = stretches[1] - m_y.segment<4>(j),
                dz = stretches[2] - m_z.segment<4>(j);
    const Lanes r2 = dx * dx + dy * dy + dz * dz + eps2;
    const Lanes inv_phi = inverse_kernels(r2, smoothed);
    const Lanes inv = m_w.segment<4>(j) * inv_phi;
    gx += inv * dx;
    gy += inv * dy;
    gz += inv * dz;
    if (hessian) {
      const Lanes inv3 = inv * inv_phi * inv_phi;
      diag += inv;
      hxx += inv3 * dx * dx;
      hyy += inv3 * dy * dy;
      hzz += inv3 * dz * dz;
      hxy += inv3 * dx * dy;
      hxz += inv3 * dx * dz;
      hyz += inv3 * dy * dz;
    }
  }
  if (hessian)
    *hessian += kernel_hessian(lane_sum(diag), lane_sum(hxx), lane_sum(hyy), lane_sum(hzz),
        lane_sum(hxy), lane_sum(hxz), lane_sum(hyz));
  return { lane_sum(gx), lane_sum(gy), lane_sum(gz) };
}

} // namespace elastolearn::material
