#pragma once
/// \file Distances from cloud points to a deformed triangle surface, to measure how well a mesh
/// follows a point cloud (the tracking report's RMS cloud → surface distance).
#include <elastolearn/capture/cloud_index.hpp>
#include <elastolearn/capture/surface_samples.hpp>

#include <vector>

namespace elastolearn::capture {

/// The distance from `p` to the triangle (a, b, c) [m] (Ericson, Real-Time Collision Detection
/// §5.1.5: the closest point in the vertex, edge or face region that contains p's projection).
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Distances from points to the surface `faces` at positions x. Each point's nearest surface
/// sample (a k-d tree over samples of the faces at x) picks the candidate triangles: those around
/// the sample's vertices; the exact distance to the nearest candidate is returned. That is the true
/// distance to the surface whenever the closest surface point lies on a triangle around the
/// nearest sample (always the case when the samples are finer than the triangles: subdivision
/// ≥ 2), and never less than it.
class SurfaceDistance {
  public:
  /// `faces` (f×3, indices < num_vertices), sampled with sample_surface(faces, subdivision).
  SurfaceDistance(const Faces& faces, int num_vertices, int subdivision = 2);

  /// The distance of every row of `points` (N×3) to the surface at x (n×3), into `out` (resized
  /// to N). Parallel over points. An empty surface gives +∞.
  void distances(ConstRef<Positions> x, ConstRef<Positions> points, VecX& out) const;
  /// √(mean squared distance) of `points` to the surface at x; 0 for no points.
  double rms(ConstRef<Positions> x, ConstRef<Positions> points) const;

  private:
  Faces m_faces;
  SurfaceSamples m_samples;
  std::vector<int> m_vertex_faces; ///< faces around each vertex, vertex v's at m_offsets[v] …
  std::vector<int> m_offsets;
};

} // namespace elastolearn::capture
