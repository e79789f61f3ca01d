// Text surface formats: Wavefront OBJ and OFF.
#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/surface_readers.hpp>

namespace elastolearn::mesh {

SurfaceMesh read_obj(const std::filesystem::path& path) {
  LineReader in(path);
  SurfaceBuilder builder(path.string());
  std::vector<long long> poly;
  while (in.next()) {
    if (in[0] == "v") {
      in.require_tokens(4, "a vertex");
      builder.add_vertex(
          in.real(1, "x coordinate"), in.real(2, "y coordinate"), in.real(3, "z coordinate"));
    } else if (in[0] == "f") {
      poly.clear();
      for (std::size_t i = 1; i < in.size(); ++i) {
        const std::string_view token = in[i].substr(0, in[i].find('/'));
        long long v = 0;
        if (!parse_integer(token, v) || v == 0)
          in.fail("invalid face vertex index '" + std::string(in[i]) + "'");
        // 1-based; negative indices count back from the last vertex read so far.
        poly.push_back(v > 0 ? v - 1 : builder.num_vertices() + v);
      }
      builder.add_polygon(poly, in.where(), /*defer_check=*/true);
    }
    // vt, vn, g, o, s, usemtl, mtllib, l, p: not needed for a closed surface
  }
  return builder.finish();
}

SurfaceMesh read_off(const std::filesystem::path& path) {
  LineReader in(path);
  in.require("the OFF header");
  const std::string_view magic = in[0];
  if (magic.size() < 3 || magic.substr(magic.size() - 3) != "OFF"
      || magic.find('4') != std::string_view::npos || magic.find('n') != std::string_view::npos)
    in.fail("not an OFF file: header '" + std::string(magic) + "'");
  std::size_t first = 1; // counts may follow the keyword on the same line
  if (in.size() < 4) {
    in.require("the OFF counts");
    first = 0;
  }
  const long long nv = in.integer(first, "number of vertices");
  const long long nf = in.integer(first + 1, "number of faces");
  if (nv <= 0 || nv >= (1LL << 31))
    in.fail("invalid number of vertices " + std::to_string(nv));
  if (nf <= 0 || nf >= (1LL << 31))
    in.fail("invalid number of faces " + std::to_string(nf));
  SurfaceBuilder builder(path.string());
  for (long long i = 0; i < nv; ++i) {
    in.require("vertex " + std::to_string(i) + " of " + std::to_string(nv));
    in.require_tokens(3, "a vertex");
    builder.add_vertex(
        in.real(0, "x coordinate"), in.real(1, "y coordinate"), in.real(2, "z coordinate"));
  }
  std::vector<long long> poly;
  for (long long f = 0; f < nf; ++f) {
    in.require("face " + std::to_string(f) + " of " + std::to_string(nf));
    const long long k = in.integer(0, "face vertex count");
    if (k < 3 || k > 1000000)
      in.fail("invalid face vertex count " + std::to_string(k));
    in.require_tokens(static_cast<std::size_t>(k + 1), "a face");
    poly.clear();
    for (long long i = 1; i <= k; ++i)
      poly.push_back(in.integer(static_cast<std::size_t>(i), "face vertex index"));
    builder.add_polygon(poly, in.where());
  }
  return builder.finish();
}

} // namespace elastolearn::mesh
