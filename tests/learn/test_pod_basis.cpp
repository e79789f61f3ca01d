// POD basis: a trajectory that moves in a 3-dimensional subspace is reproduced exactly by 3 modes,
// the modes are orthonormal (plain or mass-weighted), fixed vertices get zero rows, and options
// select frames and modes as documented.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/pod_basis.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

struct LowRankMotion {
  Positions rest;
  std::vector<Positions> frames;
  std::vector<int> free_vertices;
  VecX dof_masses;
};

/// n vertices; vertices 0 and 1 fixed; the rest move as Σ_k a_k(t) ψ_k with 3 random shapes ψ_k
/// and amplitudes of different sizes (so the singular values are distinct).
LowRankMotion low_rank_motion(int n = 40, int T = 60) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  LowRankMotion m;
  m.rest.resize(n, 3);
  for (Eigen::Index i = 0; i < m.rest.size(); ++i)
    m.rest.data()[i] = g(rng);
  MatX shapes = MatX::Zero(3 * n, 3);
  for (int k = 0; k < 3; ++k) {
    for (int d = 6; d < 3 * n; ++d) // dofs of vertices 0, 1 stay zero
      shapes(d, k) = g(rng);
  }
  for (int t = 0; t < T; ++t) {
    const Eigen::Vector3d a(
        0.1 * std::sin(0.3 * t), 0.03 * std::cos(0.7 * t), 0.01 * std::sin(1.9 * t + 1));
    VecX x = flatten(m.rest) + shapes * a;
    m.frames.emplace_back(unflatten(x));
  }
  for (int v = 2; v < n; ++v)
    m.free_vertices.push_back(v);
  m.dof_masses.resize(3 * n);
  for (int v = 0; v < n; ++v)
    m.dof_masses.segment<3>(3 * v).setConstant(0.5 + 0.05 * v);
  return m;
}

/// Largest error of projecting every frame's displacement onto span(Φ) (orthogonal in the given
/// inner product: P = Φ (ΦᵀWΦ)⁻¹ ΦᵀW, and ΦᵀWΦ = I is checked separately).
double max_projection_error(const LowRankMotion& m, const MatX& phi, const VecX& w) {
  double worst = 0;
  for (const Positions& x : m.frames) {
    const VecX d = flatten(x) - flatten(m.rest);
    const VecX p = phi * (phi.transpose() * w.asDiagonal() * d);
    worst = std::max(worst, (p - d).norm());
  }
  return worst;
}

} // namespace

TEST(PodBasis, ReproducesALowRankTrajectoryExactly) {
  const LowRankMotion m = low_rank_motion();
  PodOptions options;
  options.max_modes = 10;
  const PodBasis basis = pod_basis(m.frames, m.rest, m.free_vertices, options);
  // Rank 3: only three singular values above round-off, so only three modes are kept.
  ASSERT_EQ(basis.num_modes(), 3);
  EXPECT_LT(basis.singular_values[3], 1e-12 * basis.singular_values[0]);
  EXPECT_NEAR(basis.captured_energy, 1.0, 1e-12);
  EXPECT_LE((basis.modes.transpose() * basis.modes - MatX::Identity(3, 3)).norm(), 1e-12);
  const VecX ones = VecX::Ones(basis.modes.rows());
  EXPECT_LE(max_projection_error(m, basis.modes, ones), 1e-12);
  EXPECT_EQ(basis.modes.topRows(6).norm(), 0.0); // fixed vertices do not move
  EXPECT_EQ(int(basis.frames.size()), 60);
}

TEST(PodBasis, MassOrthonormalModes) {
  const LowRankMotion m = low_rank_motion();
  PodOptions options;
  options.mass_orthonormal = true;
  const PodBasis basis = pod_basis(m.frames, m.rest, m.free_vertices, options, m.dof_masses);
  ASSERT_EQ(basis.num_modes(), 3);
  const MatX gram = basis.modes.transpose() * m.dof_masses.asDiagonal() * basis.modes;
  EXPECT_LE((gram - MatX::Identity(3, 3)).norm(), 1e-12);
  EXPECT_LE(max_projection_error(m, basis.modes, m.dof_masses), 1e-12);
}

TEST(PodBasis, FewerModesCaptureTheDocumentedEnergy) {
  const LowRankMotion m = low_rank_motion();
  PodOptions options;
  options.max_modes = 1;
  const PodBasis one = pod_basis(m.frames, m.rest, m.free_vertices, options);
  ASSERT_EQ(one.num_modes(), 1);
  const VecX& s = one.singular_values;
  EXPECT_NEAR(one.captured_energy, s[0] * s[0] / s.squaredNorm(), 1e-14);
  EXPECT_LT(one.captured_energy, 1.0 - 1e-4); // the other two amplitudes are not negligible

  options.max_modes = 10;
  options.energy_fraction = one.captured_energy * 0.999; // reached by the first mode alone
  EXPECT_EQ(pod_basis(m.frames, m.rest, m.free_vertices, options).num_modes(), 1);
  options.energy_fraction = one.captured_energy * 1.001;
  EXPECT_EQ(pod_basis(m.frames, m.rest, m.free_vertices, options).num_modes(), 2);
}

TEST(PodBasis, SelectsFrames) {
  const LowRankMotion m = low_rank_motion();
  PodOptions options;
  options.first_frame = 10;
  options.frame_count = 20;
  options.frame_stride = 3;
  const PodBasis basis = pod_basis(m.frames, m.rest, m.free_vertices, options);
  EXPECT_EQ(basis.frames, (std::vector<int> { 10, 13, 16, 19, 22, 25, 28 }));
  EXPECT_EQ(basis.num_modes(), 3); // 7 generic frames of a rank-3 motion still span it
  EXPECT_LE(max_projection_error(m, basis.modes, VecX::Ones(basis.modes.rows())), 1e-12);
}

TEST(PodBasis, SeveralTrajectoriesShareOneBasis) {
  // A second trajectory moving along a 4th shape (as the constrained simulation adds the observed
  // shapes to the forward one's): the joint basis has 4 modes and reproduces both trajectories
  // exactly; the frame selection applies to each trajectory.
  const LowRankMotion m = low_rank_motion();
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  VecX shape = VecX::Zero(3 * m.rest.rows());
  for (Eigen::Index d = 6; d < shape.size(); ++d)
    shape[d] = g(rng);
  LowRankMotion other = m;
  for (std::size_t t = 0; t < other.frames.size(); ++t)
    other.frames[t]
        = unflatten(VecX(flatten(m.frames[t]) + 0.02 * std::cos(0.5 * double(t)) * shape));
  PodOptions options;
  options.max_modes = 10;
  options.frame_stride = 2;
  const std::vector<std::vector<Positions>> both { m.frames, other.frames };
  const PodBasis basis
      = pod_basis(std::span<const std::vector<Positions>>(both), m.rest, m.free_vertices, options);
  EXPECT_EQ(basis.num_modes(), 4);
  EXPECT_EQ(basis.frames.size(), 30u);
  const VecX ones = VecX::Ones(basis.modes.rows());
  EXPECT_LE(max_projection_error(m, basis.modes, ones), 1e-12);
  EXPECT_LE(max_projection_error(other, basis.modes, ones), 1e-12);
  // The first trajectory's own basis misses the second one's extra shape.
  const PodBasis first = pod_basis(m.frames, m.rest, m.free_vertices, options);
  EXPECT_GT(max_projection_error(other, first.modes, ones), 1e-3);
  // Trajectories of different lengths are refused.
  const std::vector<std::vector<Positions>> uneven { m.frames,
    std::vector<Positions>(m.frames.begin(), m.frames.end() - 1) };
  EXPECT_THROW(
      pod_basis(std::span<const std::vector<Positions>>(uneven), m.rest, m.free_vertices, options),
      InputError);
}

TEST(PodBasis, RejectsBadInput) {
  const LowRankMotion m = low_rank_motion(10, 5);
  PodOptions bad;
  bad.max_modes = 0;
  EXPECT_THROW(pod_basis(m.frames, m.rest, m.free_vertices, bad), InputError);
  PodOptions mass;
  mass.mass_orthonormal = true;
  EXPECT_THROW(pod_basis(m.frames, m.rest, m.free_vertices, mass), InputError); // no masses
  EXPECT_THROW(pod_basis(m.frames, m.rest, { 2, 2 }, PodOptions()), InputError); // repeated
  EXPECT_THROW(pod_basis(m.frames, m.rest, { 10 }, PodOptions()), InputError); // out of range
  PodOptions late;
  late.first_frame = 5;
  EXPECT_THROW(pod_basis(m.frames, m.rest, m.free_vertices, late), InputError); // no frame
  const std::vector<Positions> still(3, m.rest);
  EXPECT_THROW(pod_basis(still, m.rest, m.free_vertices, PodOptions()), InputError); // no motion
}
