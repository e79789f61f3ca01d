#pragma once
/// \file The per-element data of stress reconstruction (paper 000 §6.1): the rest mesh with its
/// nominal material (ReconstructionMesh), each element's principal frame and stretch rates at a
/// frame (ElementState), the principal stretches of a trajectory for choosing RBF centres
/// (collect_stretches), and the input checks of frame lists shared by the reconstruction.
#include <elastolearn/fem/dof_map.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <vector>

namespace elastolearn::learn {

/// The per-element rest data the reconstruction needs (precompute once per mesh), and the nominal
/// material whose Rayleigh damping the correction's Δα₁ adds to (Eq. 13). Its `elastic` may be
/// null when no damping is fitted or evaluated (then corrections contribute their N term only).
struct ReconstructionMesh {
  /// From a rest mesh (computes fem::precompute_rest_data). Throws InputError if `nominal` has a
  /// stiffness scale whose length is not the number of tets.
  explicit ReconstructionMesh(const mesh::TetMesh& mesh, fem::MaterialModel nominal = {});
  /// From rest data already computed (e.g. fem::ElasticForce::rest_data() and tets()).
  /// Throws InputError if `rest` and `tets` differ in length, an index is outside [0, n), or a
  /// stiffness scale's length is not the number of tets.
  ReconstructionMesh(std::vector<fem::TetRestData> rest, Tets tets, int num_vertices,
      fem::MaterialModel nominal = {});

  std::vector<fem::TetRestData> rest; ///< m
  Tets tets; ///< m × 4
  int num_vertices = 0; ///< n
  /// Elastic model, Rayleigh damping and stiffness scale, applied as fem::ElasticForce does (its
  /// correction is ignored).
  fem::MaterialModel nominal;

  int num_tets() const { return static_cast<int>(tets.rows()); }
};

/// The state of one element at one frame: principal frame F = U diag(σ) Vᵀ (σ sorted descending)
/// and stretch rates ḟ = diag(Uᵀ Ḟ V) [1/s] (paper §4.2).
struct ElementState {
  material::PrincipalFrame frame;
  Vec3 stretch_rates = Vec3::Zero();
  Mat3 deformation_rate = Mat3::Zero(); ///< Ḟ [1/s]
};

/// Element states of one frame: `x`, `v` flat 3n positions [m] and velocities [m/s]; `states` is
/// resized to m (no allocation once sized). Parallel over elements (oneTBB).
void compute_element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    std::vector<ElementState>& states);
/// The same states with each element's principal frame taken from `frames`, an element force of
/// the same mesh (same tets, same order) whose last add_force was at x
/// (fem::ElasticForce::caches_positions): the SVD it already did, bit for bit. Throws
/// std::logic_error if its cache is not at x or it has another number of tets.
void compute_element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    const fem::ElasticForce& frames, std::vector<ElementState>& states);

/// Which principal stretches collect_stretches returns.
struct StretchSampleOptions {
  int frame_stride = 1; ///< use frames 0, s, 2s, … (≥ 1)
  /// At most this many rows (≥ 0; 0 = no cap): when there are more (element, frame) samples, every
  /// ⌈N / cap⌉-th is kept, deterministically.
  Eigen::Index max_samples = 0;
  /// Throws InputError("stretch_samples.<field>", ...) for an out-of-range field.
  void validate() const;
};

/// The sorted principal stretches of every element at the selected frames, as rows of an N × 3
/// matrix (frame-major, then element), for choosing RBF centres with learn::kmeans (Eq. 10).
/// Throws InputError if a frame is not 3n long, is not finite, or the options are invalid.
MatX collect_stretches(const ReconstructionMesh& mesh, const std::vector<VecX>& positions,
    const StretchSampleOptions& options = {});

namespace detail {
/// Input checks shared by the reconstruction entry points (throws InputError).
/// `dofs` may be null (no DofMap check), as may `velocities` and `target_forces`.
void check_frames(const ReconstructionMesh& mesh, const fem::DofMap* dofs,
    const std::vector<VecX>& positions, const std::vector<VecX>* velocities,
    const std::vector<VecX>* target_forces);
/// The frame indices 0, stride, 2·stride, … below `count`.
std::vector<int> selected_frames(int count, int stride);
} // namespace detail

} // namespace elastolearn::learn
