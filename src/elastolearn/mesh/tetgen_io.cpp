#include <elastolearn/mesh/tetgen_io.hpp>

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/mesh_validation.hpp>

#include <charconv>
#include <fstream>

namespace elastolearn::mesh {

namespace {

constexpr long long kMaxCount = 1LL << 31;

long long read_count(const LineReader& in, std::size_t i, const char* what) {
  const long long n = in.integer(i, what);
  if (n < 0 || n >= kMaxCount)
    in.fail(std::string("invalid ") + what + " " + std::to_string(n));
  return n;
}

void append_number(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void write_atomic(AtomicFile& file, const std::string& contents) {
  std::ofstream out(file.temp_path(), std::ios::binary);
  out << contents;
  out.close();
  if (!out)
    throw InputError(file.target().string(), "cannot write file");
}

} // namespace

std::filesystem::path tetgen_stem(const std::filesystem::path& path) {
  const auto ext = path.extension();
  if (ext == ".node" || ext == ".ele")
    return std::filesystem::path(path).replace_extension();
  return path;
}

std::array<std::filesystem::path, 2> tetgen_files(const std::filesystem::path& path) {
  const auto stem = tetgen_stem(path);
  auto node_path = stem, ele_path = stem;
  node_path += ".node";
  ele_path += ".ele";
  return { node_path, ele_path };
}

TetMesh read_tetgen(const std::filesystem::path& path) {
  const auto [node_path, ele_path] = tetgen_files(path);

  SourceLines lines;
  LineReader nodes(node_path);
  nodes.require("the .node header");
  const long long n = read_count(nodes, 0, "number of points");
  if (n == 0)
    nodes.fail("no points (points stored in a .poly file are not supported)");
  const long long dim = nodes.size() > 1 ? nodes.integer(1, "dimension") : 3;
  if (dim != 3)
    nodes.fail("dimension must be 3, got " + std::to_string(dim));
  const long long nattr = nodes.size() > 2 ? read_count(nodes, 2, "number of attributes") : 0;
  const long long nmark = nodes.size() > 3 ? read_count(nodes, 3, "number of boundary markers") : 0;
  std::vector<double> xyz;
  long long base = 0;
  for (long long i = 0; i < n; ++i) {
    nodes.require("point " + std::to_string(i) + " of " + std::to_string(n));
    nodes.require_tokens(static_cast<std::size_t>(4 + nattr + nmark), "a point");
    const long long id = nodes.integer(0, "point id");
    if (i == 0) {
      if (id != 0 && id != 1)
        nodes.fail("first point id must be 0 or 1, got " + std::to_string(id));
      base = id;
    } else if (id != base + i) {
      nodes.fail("point ids must be consecutive: expected " + std::to_string(base + i) + ", got "
          + std::to_string(id));
    }
    for (int k = 1; k <= 3; ++k)
      xyz.push_back(nodes.real(static_cast<std::size_t>(k), "coordinate"));
    lines.vertex_lines.push_back(nodes.line_number());
  }

  LineReader eles(ele_path);
  eles.require("the .ele header");
  const long long m = read_count(eles, 0, "number of tetrahedra");
  const long long per = eles.size() > 1 ? eles.integer(1, "nodes per tetrahedron") : 4;
  if (per != 4 && per != 10)
    eles.fail("nodes per tetrahedron must be 4 or 10, got " + std::to_string(per));
  const long long eattr = eles.size() > 2 ? read_count(eles, 2, "number of attributes") : 0;
  std::vector<int> idx;
  for (long long t = 0; t < m; ++t) {
    eles.require("tetrahedron " + std::to_string(t) + " of " + std::to_string(m));
    eles.require_tokens(static_cast<std::size_t>(1 + per + eattr), "a tetrahedron");
    for (std::size_t k = 1; k <= 4; ++k) {
      const long long v = eles.integer(k, "vertex index");
      if (v < base || v >= base + n)
        eles.fail("tetrahedron " + std::to_string(t) + " has vertex index " + std::to_string(v)
            + " out of range [" + std::to_string(base) + ", " + std::to_string(base + n) + ")");
      idx.push_back(static_cast<int>(v - base));
    }
    lines.tet_lines.push_back(eles.line_number());
  }

  Positions rest = Eigen::Map<const Positions>(xyz.data(), static_cast<Eigen::Index>(n), 3);
  Tets tets = Eigen::Map<const Tets>(idx.data(), static_cast<Eigen::Index>(m), 4);
  validate_tet_mesh(rest, tets, ele_path.string(), &lines);
  return TetMesh(std::move(rest), std::move(tets), ele_path.string());
}

void write_tetgen(const std::filesystem::path& stem, const TetMesh& mesh) {
  const auto [node_path, ele_path] = tetgen_files(stem);

  std::string node = "# elastolearn rest mesh: <id> x y z (0-based)\n";
  node += std::to_string(mesh.num_vertices()) + " 3 0 0\n";
  const Positions& x = mesh.rest_positions();
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    node += std::to_string(i);
    for (int k = 0; k < 3; ++k) {
      node += ' ';
      append_number(node, x(i, k));
    }
    node += '\n';
  }
  std::string ele = "# elastolearn tets: <id> v0 v1 v2 v3, det[x1-x0, x2-x0, x3-x0] > 0\n";
  ele += std::to_string(mesh.num_tets()) + " 4 0\n";
  const Tets& t = mesh.tets();
  for (int i = 0; i < mesh.num_tets(); ++i)
    ele += std::to_string(i) + ' ' + std::to_string(t(i, 0)) + ' ' + std::to_string(t(i, 1)) + ' '
        + std::to_string(t(i, 2)) + ' ' + std::to_string(t(i, 3)) + '\n';

  AtomicFile node_file(node_path), ele_file(ele_path);
  write_atomic(node_file, node);
  write_atomic(ele_file, ele);
  node_file.commit();
  ele_file.commit();
}

} // namespace elastolearn::mesh
