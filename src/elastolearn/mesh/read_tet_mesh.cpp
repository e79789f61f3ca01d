#include <elastolearn/mesh/read_tet_mesh.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/gmsh_io.hpp>
#include <elastolearn/mesh/tetgen_io.hpp>
#include <elastolearn/mesh/vega_io.hpp>

#include <algorithm>
#include <cctype>

namespace elastolearn::mesh {

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
      [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

} // namespace

std::vector<std::filesystem::path> tet_mesh_files(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".node" || ext == ".ele") {
    const auto files = tetgen_files(path);
    return { files.begin(), files.end() };
  }
  return { path };
}

TetMesh read_tet_mesh(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
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
