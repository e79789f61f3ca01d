#pragma once
/// \file Internal: the per-format surface readers behind read_surface_mesh, and the builder they
/// share (index checks and fan triangulation in one place).
#include <elastolearn/mesh/surface_mesh.hpp>

#include <array>
#include <string>
#include <vector>

namespace elastolearn::mesh {

/// Accumulates vertices and polygons; `finish()` checks indices and returns the mesh.
class SurfaceBuilder {
  public:
  explicit SurfaceBuilder(std::string source)
      : m_source(std::move(source)) { }
  void add_vertex(double x, double y, double z) { m_xyz.insert(m_xyz.end(), { x, y, z }); }
  int num_vertices() const { return static_cast<int>(m_xyz.size() / 3); }
  /// Fan-triangulates a polygon of 0-based indices; `where` names file:line for errors.
  /// Indices are range-checked against the vertices added so far unless `defer_check`.
  void add_polygon(
      const std::vector<long long>& indices, const std::string& where, bool defer_check = false);
  /// Builds the mesh; throws InputError if there are no faces or a deferred index is out of range.
  SurfaceMesh finish();

  private:
  std::string m_source;
  std::vector<double> m_xyz;
  std::vector<std::array<int, 3>> m_faces;
  std::vector<std::string> m_face_where; ///< only for deferred checks
  std::vector<long long> m_deferred_max;
};

SurfaceMesh read_obj(const std::filesystem::path& path);
SurfaceMesh read_off(const std::filesystem::path& path);
SurfaceMesh read_ply(const std::filesystem::path& path);
SurfaceMesh read_stl(const std::filesystem::path& path);

} // namespace elastolearn::mesh
