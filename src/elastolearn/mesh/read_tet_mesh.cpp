#include <elastolearn/mesh/read_tet_mesh.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/gmsh_io.hpp>
#include <elastolearn/mesh/tetgen_io.hpp>
#include <elastolearn/mesh/vega_io.hpp>

#include <algorithm>
#include <cctype>

namespace elastolearn::mesh {

TetMesh read_tet_mesh(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
      [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".node" || ext == ".ele")
    return read_tetgen(path);
  if (ext == ".msh")
    return read_gmsh(path);
  if (ext == ".veg")
    return read_vega(path);
  throw InputError(path.string(),
      "unknown tet-mesh extension '" + ext + "' (supported: .node, .ele, .msh, .veg)");
}

} // namespace elastolearn::mesh
