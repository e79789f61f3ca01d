// Stanford PLY surfaces: element `vertex` (x, y, z) and element `face` (vertex_indices).
#include <elastolearn/mesh/ply_reader.hpp>
#include <elastolearn/mesh/surface_readers.hpp>

#include <cmath>

namespace elastolearn::mesh {

SurfaceMesh read_ply(const std::filesystem::path& path) {
  PlyReader ply(path);
  SurfaceBuilder builder(path.string());
  std::vector<long long> poly;
  bool have_faces_element = false;
  for (const PlyElement& e : ply.elements()) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    have_faces_element |= is_face;
    for (long long i = 0; i < e.count; ++i) {
      ply.begin_record(e.name + " " + std::to_string(i) + " of " + std::to_string(e.count));
      double xyz[3] = { 0, 0, 0 };
      int found = 0;
      for (const PlyProperty& p : e.props) {
        if (!p.list) {
          const double v = ply.value(p.type);
          const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
          if (is_vertex && axis >= 0) {
            if (!std::isfinite(v))
              throw InputError(ply.where(),
                  "non-finite " + p.name + " coordinate of vertex " + std::to_string(i));
            xyz[axis] = v;
            found |= 1 << axis;
          }
          continue;
        }
        const bool indices = is_face && (p.name == "vertex_indices" || p.name == "vertex_index");
        if (!indices) {
          ply.skip(p);
          continue;
        }
        const double count = ply.value(p.count_type);
        if (!(count >= 0 && count <= 1e6))
          throw InputError(ply.where(), "invalid list length in " + e.name);
        poly.clear();
        for (int k = 0; k < static_cast<int>(count); ++k)
          poly.push_back(static_cast<long long>(ply.value(p.type)));
        builder.add_polygon(poly, ply.where() + " (face " + std::to_string(i) + ")");
      }
      if (is_vertex) {
        if (found != 7)
          throw InputError(path.string(), "PLY vertex element lacks x, y or z");
        builder.add_vertex(xyz[0], xyz[1], xyz[2]);
      }
    }
  }
  if (!have_faces_element)
    throw InputError(path.string(), "PLY file has no face element");
  return builder.finish();
}

} // namespace elastolearn::mesh
