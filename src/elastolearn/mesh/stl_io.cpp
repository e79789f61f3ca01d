// STL surfaces, ASCII and binary. STL stores each triangle's corners separately; corners with
// identical coordinates are welded into one vertex so that closedness can be checked.
#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/surface_readers.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <map>

namespace elastolearn::mesh {

namespace {

/// Welds identical corner coordinates (exact comparison; STL repeats them bit for bit).
class Welder {
  public:
  explicit Welder(SurfaceBuilder& b)
      : m_builder(b) { }
  long long index(double x, double y, double z) {
    const auto [it, inserted]
        = m_index.emplace(std::array<double, 3> { x, y, z }, m_builder.num_vertices());
    if (inserted)
      m_builder.add_vertex(x, y, z);
    return it->second;
  }

  private:
  SurfaceBuilder& m_builder;
  std::map<std::array<double, 3>, int> m_index;
};

std::uint32_t le32(const std::string& d, std::size_t pos) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i)
    v |= static_cast<std::uint32_t>(
             static_cast<unsigned char>(d[pos + static_cast<std::size_t>(i)]))
        << (8 * i);
  return v;
}

SurfaceMesh read_binary_stl(const std::filesystem::path& path, const std::string& data) {
  if (data.size() < 84)
    throw InputError(path.string(), "truncated binary STL (shorter than its 84-byte header)");
  const std::uint32_t n = le32(data, 80);
  const std::size_t expected = 84 + 50 * static_cast<std::size_t>(n);
  if (data.size() != expected)
    throw InputError(path.string(),
        "binary STL header says " + std::to_string(n) + " triangles (" + std::to_string(expected)
            + " bytes) but the file has " + std::to_string(data.size()) + " bytes (truncated?)");
  SurfaceBuilder builder(path.string());
  Welder welder(builder);
  std::vector<long long> tri(3);
  for (std::uint32_t t = 0; t < n; ++t) {
    const std::size_t base = 84 + 50 * static_cast<std::size_t>(t) + 12; // skip the normal
    for (int c = 0; c < 3; ++c) {
      double x[3];
      for (int k = 0; k < 3; ++k) {
        x[k] = std::bit_cast<float>(
            le32(data, base + 12 * static_cast<std::size_t>(c) + 4 * static_cast<std::size_t>(k)));
        if (!std::isfinite(x[k]))
          throw InputError(path.string(), "non-finite coordinate in triangle " + std::to_string(t));
      }
      tri[static_cast<std::size_t>(c)] = welder.index(x[0], x[1], x[2]);
    }
    builder.add_polygon(tri, path.string() + " (triangle " + std::to_string(t) + ")");
  }
  return builder.finish();
}

SurfaceMesh read_ascii_stl(const std::filesystem::path& path, std::string data) {
  LineReader in(path.string(), std::move(data), '\0');
  SurfaceBuilder builder(path.string());
  Welder welder(builder);
  in.require("the 'solid' line");
  std::vector<long long> loop;
  bool in_loop = false;
  for (;;) {
    in.require("the next facet (no 'endsolid')");
    const std::string_view key = in[0];
    if (key == "endsolid")
      break;
    if (key == "facet" || key == "endfacet")
      continue;
    if (key == "outer") {
      loop.clear();
      in_loop = true;
    } else if (key == "vertex") {
      if (!in_loop)
        in.fail("'vertex' outside 'outer loop'");
      in.require_tokens(4, "a vertex");
      loop.push_back(welder.index(
          in.real(1, "x coordinate"), in.real(2, "y coordinate"), in.real(3, "z coordinate")));
    } else if (key == "endloop") {
      if (!in_loop)
        in.fail("'endloop' without 'outer loop'");
      builder.add_polygon(loop, in.where());
      in_loop = false;
    } else {
      in.fail("unexpected STL line '" + std::string(in.line()) + "'");
    }
  }
  return builder.finish();
}

} // namespace

SurfaceMesh read_stl(const std::filesystem::path& path) {
  std::string data = read_text_file(path);
  // A binary file may also begin with "solid"; its exact size decides.
  const bool binary_size
      = data.size() >= 84 && data.size() == 84 + 50 * static_cast<std::size_t>(le32(data, 80));
  // An ASCII file starts with "solid" and soon has a "facet" (or is an empty "endsolid").
  const std::string_view head = std::string_view(data).substr(0, 1024);
  const bool looks_ascii = head.starts_with("solid")
      && (head.find("facet") != std::string_view::npos
          || head.find("endsolid") != std::string_view::npos);
  if (looks_ascii && !binary_size)
    return read_ascii_stl(path, std::move(data));
  return read_binary_stl(path, data);
}

} // namespace elastolearn::mesh
