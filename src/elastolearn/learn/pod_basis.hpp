#pragma once
/// \file Proper orthogonal decomposition (paper 000 §5.1): the reduced basis Φ of the sparse
/// reduced space-time optimisation, x_i = x̄ + Φ z_i, from the principal components of a forward
/// simulation's free-vertex displacements (a fraction of its frames, a fraction of the modes).
#include <elastolearn/core/types.hpp>

#include <span>
#include <vector>

namespace elastolearn::learn {

/// Which snapshots and how many modes.
struct PodOptions {
  int max_modes = 20; ///< r is at most this (≥ 1)
  /// Keep the fewest modes whose captured energy reaches this fraction (0 < f ≤ 1), still at most
  /// max_modes; 1 keeps max_modes (or the snapshot rank, if smaller).
  double energy_fraction = 1.0;
  int first_frame = 0; ///< first snapshot frame (≥ 0)
  int frame_count = 0; ///< frames from first_frame on (0 = to the end): the "short portion"
  int frame_stride = 1; ///< use every k-th of those frames (≥ 1)
  /// Orthonormal in the lumped-mass inner product (Φᵀ M Φ = I) instead of Φᵀ Φ = I.
  bool mass_orthonormal = false;
  /// Modes whose singular value is ≤ rank_tolerance · (largest) are numerical noise, never kept.
  double rank_tolerance = 1e-10;
  /// Throws InputError("pod.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The reduced basis and what it captures.
struct PodBasis {
  /// 3n × r, columns orthonormal (Φᵀ Φ = I, or Φᵀ M Φ = I when mass-orthonormal), dofs ordered
  /// as flatten(Positions); rows of vertices that are not free are zero.
  MatX modes;
  /// All singular values of the (mass-weighted) snapshot matrix, descending [m·√kg or m].
  VecX singular_values;
  /// Σ_{i<r} s_i² / Σ_i s_i²: the fraction of the snapshots' squared norm the r modes reproduce.
  double captured_energy = 0;
  /// The frame indices used as snapshots.
  std::vector<int> frames;

  int num_modes() const { return static_cast<int>(modes.cols()); }
};

/// POD of the displacements x_t − rest of `free_vertices` over the selected frames (not
/// mean-centred, so rest + span(Φ) contains every snapshot the kept modes capture), via Eigen's
/// BDCSVD of the 3|free| × T' snapshot matrix (√M-weighted when mass-orthonormal: Φ = M^{-1/2} U).
/// \param frames  T frames, each n×3 [m]
/// \param rest  n×3 rest positions [m]
/// \param free_vertices  the vertices whose motion the basis spans (e.g. not fixed/keyframed)
/// \param dof_masses  lumped mass per dof (3n, all > 0 at free vertices); needed only when
///        options.mass_orthonormal (else may be empty)
/// Throws InputError for invalid options, inconsistent sizes, a vertex index out of range,
/// missing masses, no selected frame, or snapshots that do not move at all (no mode to keep).
PodBasis pod_basis(const std::vector<Positions>& frames, ConstRef<Positions> rest,
    const std::vector<int>& free_vertices, const PodOptions& options,
    ConstRef<VecX> dof_masses = VecX());

/// The same over several trajectories of equal length (e.g. a simulation and the constrained
/// simulation that follows the observations): the frame selection applies to each trajectory,
/// and all their selected frames are the snapshots; `frames` lists the selection once.
/// Throws InputError also if there is no trajectory or their lengths differ.
PodBasis pod_basis(std::span<const std::vector<Positions>> trajectories, ConstRef<Positions> rest,
    const std::vector<int>& free_vertices, const PodOptions& options,
    ConstRef<VecX> dof_masses = VecX());

} // namespace elastolearn::learn
