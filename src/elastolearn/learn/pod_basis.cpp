#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/pod_basis.hpp>

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors pod_error("pod");

} // namespace

void PodOptions::validate() const {
  if (max_modes < 1)
    pod_error("max_modes", "must be at least 1, got " + to_text(max_modes));
  if (!(energy_fraction > 0 && energy_fraction <= 1))
    pod_error("energy_fraction", "must be in (0, 1], got " + to_text(energy_fraction));
  if (first_frame < 0)
    pod_error("first_frame", "must be ≥ 0, got " + to_text(first_frame));
  if (frame_count < 0)
    pod_error("frame_count", "must be ≥ 0 (0 = all), got " + to_text(frame_count));
  if (frame_stride < 1)
    pod_error("frame_stride", "must be at least 1, got " + to_text(frame_stride));
  if (!(rank_tolerance >= 0 && rank_tolerance < 1))
    pod_error("rank_tolerance", "must be in [0, 1), got " + to_text(rank_tolerance));
}

PodBasis pod_basis(const std::vector<Positions>& frames, ConstRef<Positions> rest,
    const std::vector<int>& free_vertices, const PodOptions& options, ConstRef<VecX> dof_masses) {
  return pod_basis(std::span<const std::vector<Positions>>(&frames, 1), rest, free_vertices,
      options, dof_masses);
}

PodBasis pod_basis(std::span<const std::vector<Positions>> trajectories, ConstRef<Positions> rest,
    const std::vector<int>& free_vertices, const PodOptions& options, ConstRef<VecX> dof_masses) {
  options.validate();
  const Eigen::Index n = rest.rows();
  if (trajectories.empty())
    pod_error("frames", "no trajectory");
  const std::vector<Positions>& frames = trajectories.front();
  for (std::size_t k = 0; k < trajectories.size(); ++k) {
    if (trajectories[k].size() != frames.size()) {
      pod_error("frames",
          "trajectory " + to_text(k) + " has " + to_text(trajectories[k].size())
              + " frames, the first " + "has " + to_text(frames.size()));
    }
    for (std::size_t t = 0; t < trajectories[k].size(); ++t) {
      if (trajectories[k][t].rows() != n) {
        pod_error("frames",
            "frame " + to_text(t) + " has " + to_text(trajectories[k][t].rows())
                + " vertices, the rest " + "shape has " + to_text(n));
      }
    }
  }
  for (int v : free_vertices) {
    if (v < 0 || v >= n)
      pod_error(
          "free_vertices", "vertex " + to_text(v) + " is out of range [0, " + to_text(n) + ")");
  }
  if (free_vertices.empty())
    pod_error("free_vertices", "no free vertex: nothing to reduce");
  {
    std::vector<int> sorted = free_vertices;
    std::sort(sorted.begin(), sorted.end());
    const auto repeated = std::adjacent_find(sorted.begin(), sorted.end());
    if (repeated != sorted.end())
      pod_error("free_vertices", "vertex " + to_text(*repeated) + " is listed twice");
  }
  if (options.mass_orthonormal) {
    if (dof_masses.size() != 3 * n)
      pod_error("dof_masses",
          "need 3n = " + to_text(3 * n) + " masses, got " + to_text(dof_masses.size()));
    for (int v : free_vertices) {
      for (int c = 0; c < 3; ++c) {
        if (!(dof_masses[3 * v + c] > 0))
          pod_error("dof_masses", "mass of vertex " + to_text(v) + " is not positive");
      }
    }
  }

  PodBasis basis;
  const int total = static_cast<int>(frames.size());
  const int end = options.frame_count > 0
      ? std::min(total, options.first_frame + options.frame_count)
      : total;
  for (int t = options.first_frame; t < end; t += options.frame_stride)
    basis.frames.push_back(t);
  if (basis.frames.empty()) {
    pod_error("first_frame",
        "selects no frame of " + to_text(total) + " (first_frame " + to_text(options.first_frame)
            + ")");
  }

  // Snapshot matrix: row 3j + c ↔ free vertex j, component c; column s ↔ frame basis.frames[s].
  const Eigen::Index m = 3 * Eigen::Index(free_vertices.size());
  const Eigen::Index per_trajectory = Eigen::Index(basis.frames.size());
  const Eigen::Index s_count = per_trajectory * Eigen::Index(trajectories.size());
  VecX weight = VecX::Ones(m);
  if (options.mass_orthonormal) {
    for (std::size_t j = 0; j < free_vertices.size(); ++j) {
      for (int c = 0; c < 3; ++c)
        weight[3 * j + c] = std::sqrt(dof_masses[3 * free_vertices[j] + c]);
    }
  }
  MatX snapshots(m, s_count);
  for (Eigen::Index s = 0; s < s_count; ++s) {
    const Positions& x = trajectories[s / per_trajectory][basis.frames[s % per_trajectory]];
    for (std::size_t j = 0; j < free_vertices.size(); ++j) {
      const int v = free_vertices[j];
      for (int c = 0; c < 3; ++c)
        snapshots(3 * j + c, s) = weight[3 * j + c] * (x(v, c) - rest(v, c));
    }
  }
  if (!snapshots.allFinite())
    pod_error("frames", "non-finite displacement in the snapshots");

  const Eigen::BDCSVD<MatX> svd(snapshots, Eigen::ComputeThinU);
  basis.singular_values = svd.singularValues();
  const VecX& sv = basis.singular_values;
  const double total_energy = sv.squaredNorm();
  if (sv.size() == 0 || !(sv[0] > 0))
    pod_error("frames", "the selected frames do not move (all displacements are zero): no mode");
  int rank = 0;
  while (rank < sv.size() && sv[rank] > options.rank_tolerance * sv[0])
    ++rank;
  int r = 0;
  double captured = 0;
  while (r < std::min(rank, options.max_modes)) {
    captured += sv[r] * sv[r];
    ++r;
    if (options.energy_fraction < 1 && captured >= options.energy_fraction * total_energy)
      break;
  }
  basis.captured_energy = captured / total_energy;

  basis.modes = MatX::Zero(3 * n, r);
  const MatX& u = svd.matrixU();
  for (std::size_t j = 0; j < free_vertices.size(); ++j) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Index row = 3 * Eigen::Index(j) + c;
      basis.modes.row(3 * Eigen::Index(free_vertices[j]) + c) = u.row(row).head(r) / weight[row];
    }
  }
  return basis;
}

} // namespace elastolearn::learn
