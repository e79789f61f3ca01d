#pragma once
/// \file Points on a triangle surface at fixed barycentric coordinates: the surface points s_k
/// of paper 000 Eq. (9). The paper matches cloud points to mesh vertices; when the mesh is coarse
/// relative to the cloud (edges longer than the cloud's point spacing), a cloud point in the
/// middle of a face is far from every vertex, so we also place points on the edges and faces.
/// Each sample is a fixed linear combination of three vertices, so it moves with the mesh and its
/// derivative with respect to the vertex positions is its barycentric weights.
#include <elastolearn/core/types.hpp>

namespace elastolearn::capture {

/// K samples: sample k is Σ_j weights(k, j) · x[vertices(k, j)], j = 0, 1, 2, with
/// weights ≥ 0 summing to 1 (a vertex sample is (v, v, v) with weights (1, 0, 0)).
struct SurfaceSamples {
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> vertices; ///< K×3
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> weights; ///< K×3

  int num_samples() const { return static_cast<int>(vertices.rows()); }

  /// Sample positions (K×3 [m]) for vertex positions x (n×3), into `out` (resized).
  void positions(ConstRef<Positions> x, Positions& out) const;
  Positions positions(ConstRef<Positions> x) const;

  /// Add Σ_k weights(k, j) · per_sample.row(k) to row vertices(k, j) of `per_vertex` (n×3): the
  /// chain rule from samples to vertices (per_sample is ∂E/∂s, per_vertex receives ∂E/∂x).
  void scatter(ConstRef<Positions> per_sample, Positions& per_vertex) const;
};

/// Unit normals of the samples (K×3) of the surface `faces` at vertex positions x (n×3): the
/// area-weighted vertex normals interpolated with the samples' barycentric weights and normalised
/// (orientation as the faces' winding). A sample whose interpolated normal vanishes gets (0, 0, 0).
Positions sample_normals(const SurfaceSamples& samples, const Faces& faces, ConstRef<Positions> x);

/// Samples of the surface `faces` (f×3 vertex indices ≥ 0) on the barycentric lattice of step
/// 1/subdivision: every vertex used by a face (once, ascending), then subdivision − 1 points on
/// every edge (once per undirected edge, at i/s from its smaller-index end), then the interior
/// lattice points (i, j, k)/s, i, j, k ≥ 1, of every face. subdivision = 1 gives the vertices
/// only (the paper's choice). Throws InputError("surface samples", ...) for subdivision outside
/// [1, 64] or a negative index.
SurfaceSamples sample_surface(const Faces& faces, int subdivision);

/// The smallest subdivision s ∈ [1, 64] for which the lattice step of the longest surface edge
/// at positions x (n×3), longest / s, is at most `spacing` [m] (> 0). Throws InputError for a
/// spacing that is not positive and finite.
int subdivision_for_spacing(ConstRef<Positions> x, const Faces& faces, double spacing);

} // namespace elastolearn::capture
