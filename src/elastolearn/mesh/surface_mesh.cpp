#include <elastolearn/mesh/surface_mesh.hpp>

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/surface_readers.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <unordered_map>

namespace elastolearn::mesh {

void SurfaceBuilder::add_polygon(
    const std::vector<long long>& indices, const std::string& where, bool defer_check) {
  if (indices.size() < 3)
    throw InputError(
        where, "a face needs at least 3 vertices, got " + std::to_string(indices.size()));
  for (long long v : indices) {
    if (v < 0 || v >= (1LL << 31) || (!defer_check && v >= num_vertices()))
      throw InputError(where,
          "face vertex index " + std::to_string(v) + " out of range [0, "
              + std::to_string(num_vertices()) + ")");
  }
  for (std::size_t i = 1; i + 1 < indices.size(); ++i) {
    const std::array<int, 3> f { static_cast<int>(indices[0]), static_cast<int>(indices[i]),
      static_cast<int>(indices[i + 1]) };
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
      continue;
    m_faces.push_back(f);
    if (defer_check) {
      m_face_where.push_back(where);
      m_deferred_max.push_back(*std::max_element(indices.begin(), indices.end()));
    }
  }
}

SurfaceMesh SurfaceBuilder::finish() {
  for (std::size_t i = 0; i < m_deferred_max.size(); ++i)
    if (m_deferred_max[i] >= num_vertices())
      throw InputError(m_face_where[i],
          "face vertex index " + std::to_string(m_deferred_max[i]) + " out of range [0, "
              + std::to_string(num_vertices()) + ")");
  if (m_faces.empty())
    throw InputError(m_source, "no faces");
  SurfaceMesh s;
  s.vertices = Eigen::Map<const Positions>(m_xyz.data(), num_vertices(), 3);
  s.faces.resize(static_cast<Eigen::Index>(m_faces.size()), 3);
  for (std::size_t i = 0; i < m_faces.size(); ++i)
    for (int k = 0; k < 3; ++k)
      s.faces(static_cast<Eigen::Index>(i), k) = m_faces[i][k];
  return s;
}

SurfaceMesh read_surface_mesh(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
      [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj")
    return read_obj(path);
  if (ext == ".off")
    return read_off(path);
  if (ext == ".ply")
    return read_ply(path);
  if (ext == ".stl")
    return read_stl(path);
  throw InputError(path.string(),
      "unknown surface-mesh extension '" + ext + "' (supported: .obj, .off, .ply, .stl)");
}

void write_off(const std::filesystem::path& path, const SurfaceMesh& surface) {
  std::string text = "OFF\n" + std::to_string(surface.vertices.rows()) + " "
      + std::to_string(surface.faces.rows()) + " 0\n";
  char buf[32];
  for (Eigen::Index i = 0; i < surface.vertices.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const auto r = std::to_chars(buf, buf + sizeof buf, surface.vertices(i, k));
      text.append(buf, r.ptr);
      text += k < 2 ? ' ' : '\n';
    }
  }
  for (Eigen::Index f = 0; f < surface.faces.rows(); ++f)
    text += "3 " + std::to_string(surface.faces(f, 0)) + " " + std::to_string(surface.faces(f, 1))
        + " " + std::to_string(surface.faces(f, 2)) + "\n";
  write_text_file_atomic(path, text);
}

EdgeDefects edge_defects(const SurfaceMesh& surface) {
  std::unordered_map<long long, int> edges;
  edges.reserve(static_cast<std::size_t>(surface.faces.rows()) * 3);
  for (Eigen::Index f = 0; f < surface.faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const long long a = surface.faces(f, k), b = surface.faces(f, (k + 1) % 3);
      ++edges[std::min(a, b) << 32 | std::max(a, b)];
    }
  EdgeDefects d;
  for (const auto& e : edges) {
    d.boundary_edges += e.second == 1;
    d.non_manifold_edges += e.second > 2;
  }
  return d;
}

bool is_closed(const SurfaceMesh& surface) {
  const EdgeDefects d = edge_defects(surface);
  return surface.faces.rows() > 0 && d.boundary_edges == 0 && d.non_manifold_edges == 0;
}

double enclosed_volume(const SurfaceMesh& surface) {
  double v = 0;
  for (Eigen::Index f = 0; f < surface.faces.rows(); ++f) {
    const Vec3 a = surface.vertices.row(surface.faces(f, 0));
    const Vec3 b = surface.vertices.row(surface.faces(f, 1));
    const Vec3 c = surface.vertices.row(surface.faces(f, 2));
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

SurfaceMesh remove_unreferenced_vertices(const SurfaceMesh& surface) {
  std::vector<int> map(static_cast<std::size_t>(surface.vertices.rows()), -1);
  for (Eigen::Index i = 0; i < surface.faces.size(); ++i)
    map[static_cast<std::size_t>(surface.faces.data()[i])] = 0;
  int n = 0;
  for (int& m : map)
    if (m == 0)
      m = n++;
  SurfaceMesh out;
  out.vertices.resize(n, 3);
  for (std::size_t i = 0; i < map.size(); ++i)
    if (map[i] >= 0)
      out.vertices.row(map[i]) = surface.vertices.row(static_cast<Eigen::Index>(i));
  out.faces = surface.faces;
  for (Eigen::Index i = 0; i < out.faces.size(); ++i)
    out.faces.data()[i] = map[static_cast<std::size_t>(out.faces.data()[i])];
  return out;
}

} // namespace elastolearn::mesh
