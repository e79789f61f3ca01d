#pragma once
/// \file Visible-vertex observations (paper 000 §7, DESIGN.md "Observations"): a fraction of the
/// surface vertices (the paper uses 100 %, 13 % and 6 %), spread over the surface, observed at
/// every frame of a trajectory with optional Gaussian noise.
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/observe/observation.hpp>

#include <cstdint>
#include <vector>

namespace elastolearn::observe {

/// Farthest-point sampling: `count` of the `candidates` (indices into the rows of `points`),
/// chosen greedily so that each new one is the candidate farthest (Euclidean) from those already
/// chosen; the first is drawn uniformly from `candidates` with std::mt19937_64(seed). Ties go to
/// the earlier candidate, so the result depends only on the inputs and the seed.
/// Returns the chosen indices sorted ascending. O(count · |candidates|).
/// Throws InputError if count ∉ [1, |candidates|] or a candidate is not a row of `points`.
std::vector<int> farthest_point_sample(
    ConstRef<Positions> points, const std::vector<int>& candidates, int count, std::uint64_t seed);

/// Number of vertices a fraction selects: round(fraction · n_surface), at least 1.
/// Throws InputError("visible fraction", ...) unless 0 < fraction ≤ 1.
int visible_vertex_count(double fraction, int num_surface_vertices);

/// A fraction (0, 1] of the mesh's surface vertices, spread over the surface by farthest-point
/// sampling on the rest positions (see farthest_point_sample). fraction = 1 gives every surface
/// vertex. Sorted ascending. Throws InputError for a fraction outside (0, 1].
std::vector<int> select_visible_vertices(
    const mesh::TetMesh& mesh, double fraction, std::uint64_t seed);

/// Observe vertices `ids` in every frame of a trajectory (frames n×3 [m], spaced dt [s], the first
/// at start_time [s]), adding independent Gaussian noise of standard deviation noise_sigma [m] to
/// every coordinate (std::mt19937_64(seed) + std::normal_distribution, drawn frame by frame, vertex
/// by vertex, x-y-z; no noise and no draws when noise_sigma = 0).
/// The result passes Observation::validate(n, T, dt, ...). Throws InputError if an id is out of
/// range, duplicated, the frames disagree in size, or noise_sigma is negative or not finite.
Observation observe_vertices(const std::vector<Positions>& frames, double dt,
    const std::vector<int>& ids, double noise_sigma, std::uint64_t seed, double start_time = 0);

} // namespace elastolearn::observe
