#include <elastolearn/core/error.hpp>
#include <elastolearn/io/trajectory_observation.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/observe/marker_dropout.hpp>
#include <elastolearn/observe/mesh_embedding.hpp>
#include <elastolearn/observe/visible_vertices.hpp>

#include <charconv>

namespace elastolearn::io {

namespace {

/// Shortest text that reads back as `v` (the file's metadata are strings).
std::string exact(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

} // namespace

TrajectoryObservation observe_trajectory(const TrajectoryData& trajectory,
    const std::string& source, const ObservationRequest& request) {
  if (trajectory.tets.rows() == 0) {
    throw InputError(source + ": /tets",
        "missing: observing needs the tet mesh to know the surface (simulate a scene to get one)");
  }
  const mesh::TetMesh moving(trajectory.rest_positions, trajectory.tets, source);
  const double dt = observe::uniform_time_step(trajectory.time, source + ": /time");
  // Observing another mesh: its vertices follow the trajectory's tets that hold them at rest.
  std::vector<Positions> onto_frames;
  if (request.onto) {
    const observe::MeshEmbedding embedding = observe::embed_points(moving,
        request.onto->rest_positions(), request.onto_tolerance * moving.bounding_box_diagonal(),
        request.onto_source + ": vertex");
    onto_frames.reserve(trajectory.positions.size());
    for (const Positions& frame : trajectory.positions)
      onto_frames.push_back(embedding.map(moving.tets(), frame));
  }
  const mesh::TetMesh& mesh = request.onto ? *request.onto : moving;
  const std::vector<Positions>& frames = request.onto ? onto_frames : trajectory.positions;

  std::vector<int> ids;
  if (request.all_vertices) {
    ids.resize(mesh.num_vertices());
    for (int i = 0; i < mesh.num_vertices(); ++i)
      ids[i] = i;
  } else if (request.vertices) {
    ids = *request.vertices;
    for (int id : ids) {
      if (id < 0 || id >= mesh.num_vertices()) {
        throw InputError(request.vertices_source,
            "vertex id " + std::to_string(id) + " is out of range [0, "
                + std::to_string(mesh.num_vertices()) + ") of the mesh in "
                + (request.onto ? request.onto_source : source));
      }
    }
  } else {
    ids = observe::select_visible_vertices(mesh, request.visible_fraction, request.seed);
  }
  TrajectoryObservation result;
  result.observation = observe::observe_vertices(
      frames, dt, ids, request.noise, request.seed, trajectory.time.front());
  observe::drop_markers(
      result.observation, request.dropout, request.dropout_burst, request.seed + 1);
  const std::string selection = request.all_vertices ? "all vertices"
      : request.vertices
      ? "vertex list " + request.vertices_source
      : "visible fraction " + exact(request.visible_fraction) + " (farthest-point sampling)";
  result.metadata = { { "source", source }, { "selection", selection },
    { "noise_sigma", exact(request.noise) }, { "seed", std::to_string(request.seed) } };
  if (request.onto)
    result.metadata["onto"] = request.onto_source;
  if (request.dropout > 0) {
    result.metadata["dropout"] = exact(request.dropout);
    result.metadata["dropout_burst"] = exact(request.dropout_burst);
  }
  result.surface_vertices = static_cast<int>(mesh.surface_vertices().size());
  result.size = mesh.bounding_box_diagonal();
  return result;
}

} // namespace elastolearn::io
