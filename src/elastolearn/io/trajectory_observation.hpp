#pragma once
/// \file Observations of a recorded trajectory (paper 000 §7, docs/observations.md): some surface
/// vertices of the trajectory's tet mesh, chosen by the caller or spread over the surface, with
/// optional Gaussian noise. What `elastolearn observe` and the Python `observe` run.
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/observe/observation.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// Which vertices to observe and how.
struct ObservationRequest {
  /// Vertex ids to observe, or nothing: `visible_fraction` of the surface vertices by
  /// farthest-point sampling.
  std::optional<std::vector<int>> vertices;
  /// Where `vertices` came from (a file name; names them in messages and the metadata).
  std::string vertices_source = "vertices";
  /// Observe every vertex (interior ones too) instead of `vertices` or `visible_fraction`.
  bool all_vertices = false;
  double visible_fraction = 0; ///< (0, 1], used when `vertices` is empty
  /// Observe the vertices of this mesh instead of the trajectory's (e.g. a coarse mesh of the same
  /// object, paper 000 §7.3): each is carried by the trajectory's tet that contains it at rest
  /// (observe::embed_points, tolerance `onto_tolerance` × the trajectory mesh's size); ids,
  /// `visible_fraction` and `all_vertices` then refer to this mesh. Not owned.
  const mesh::TetMesh* onto = nullptr;
  std::string onto_source = "onto"; ///< names `onto` in messages and the metadata
  double onto_tolerance = 1e-6;
  double noise = 0; ///< Gaussian noise standard deviation per coordinate [m], ≥ 0
  std::uint64_t seed = 1; ///< seed of the vertex choice and the noise
  /// Occlusion bursts (observe::drop_markers): the fraction of (frame, vertex) entries lost, in
  /// bursts of this mean length [frames]; drawn from the stream seed + 1, so adding it leaves the
  /// noise unchanged. 0: none.
  double dropout = 0;
  double dropout_burst = 5;
};

/// An observation with what a user is told about it.
struct TrajectoryObservation {
  observe::Observation observation;
  /// The observation file's metadata: source, selection, noise_sigma, seed (and dropout,
  /// dropout_burst when entries were dropped).
  std::map<std::string, std::string> metadata;
  int surface_vertices = 0; ///< of the observed mesh (the trajectory's, or `onto`)
  double size = 0; ///< rest bounding-box diagonal [m] of the observed mesh
};

/// Observe `trajectory` (read from `source`, which names it in messages and the metadata).
/// Throws InputError naming `source` (no /tets, uneven /time, an invalid mesh),
/// `request.vertices_source` (an id out of the mesh's range) or `request.onto_source` and the
/// vertex that lies outside the trajectory's mesh, and for a fraction outside (0, 1] or a
/// negative noise.
TrajectoryObservation observe_trajectory(
    const TrajectoryData& trajectory, const std::string& source, const ObservationRequest& request);

} // namespace elastolearn::io
