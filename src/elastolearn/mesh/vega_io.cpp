#include <elastolearn/mesh/vega_io.hpp>

#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/mesh_validation.hpp>

namespace elastolearn::mesh {

namespace {

long long read_count(const LineReader& in, const char* what) {
  const long long n = in.integer(0, what);
  if (n <= 0 || n >= (1LL << 31))
    in.fail(std::string("invalid ") + what + " " + std::to_string(n));
  return n;
}

} // namespace

TetMesh read_vega(const std::filesystem::path& path) {
  LineReader in(path);
  in.split_on_commas(true);
  SourceLines lines;
  std::vector<double> xyz;
  std::vector<int> idx;
  long long n = -1, m = -1;
  bool have_line = in.next();
  while (have_line) {
    const std::string_view key = in[0];
    if (key == "*VERTICES") {
      if (n >= 0)
        in.fail("second *VERTICES section");
      in.require("the *VERTICES header");
      n = read_count(in, "number of vertices");
      if (in.size() > 1 && in.integer(1, "dimension") != 3)
        in.fail("dimension must be 3");
      for (long long i = 0; i < n; ++i) {
        in.require("vertex " + std::to_string(i + 1) + " of " + std::to_string(n));
        if (in[0].starts_with('*'))
          in.fail("truncated *VERTICES section: expected " + std::to_string(n) + " vertices, found "
              + std::to_string(i));
        in.require_tokens(4, "a vertex");
        if (in.integer(0, "vertex id") != i + 1)
          in.fail("vertex ids must be consecutive from 1: expected " + std::to_string(i + 1)
              + ", got " + std::string(in[0]));
        for (std::size_t k = 1; k <= 3; ++k)
          xyz.push_back(in.real(k, "coordinate"));
        lines.vertex_lines.push_back(in.line_number());
      }
      have_line = in.next();
    } else if (key == "*ELEMENTS") {
      if (m >= 0)
        in.fail("second *ELEMENTS section");
      in.require("the *ELEMENTS type");
      if (in[0] != "TET")
        in.fail("only TET elements are supported, got '" + std::string(in[0]) + "'");
      in.require("the *ELEMENTS header");
      m = read_count(in, "number of elements");
      if (in.size() > 1 && in.integer(1, "nodes per element") != 4)
        in.fail("TET elements must have 4 nodes, header says " + std::string(in[1]));
      for (long long t = 0; t < m; ++t) {
        in.require("element " + std::to_string(t + 1) + " of " + std::to_string(m));
        if (in[0].starts_with('*'))
          in.fail("truncated *ELEMENTS section: expected " + std::to_string(m) + " elements, found "
              + std::to_string(t));
        in.require_tokens(5, "a TET element");
        for (std::size_t k = 1; k <= 4; ++k) {
          const long long v = in.integer(k, "vertex id");
          // Range is checked after the whole file is read (*ELEMENTS may precede *VERTICES).
          if (v < 1 || v >= (1LL << 31))
            in.fail("element " + std::to_string(t + 1) + " has vertex id " + std::to_string(v)
                + " < 1");
          idx.push_back(static_cast<int>(v - 1));
        }
        lines.tet_lines.push_back(in.line_number());
      }
      have_line = in.next();
    } else if (key == "*INCLUDE") {
      in.fail("*INCLUDE is not supported; inline the included file");
    } else {
      have_line = in.next(); // other sections and their data lines are skipped
    }
  }
  if (n < 0)
    throw InputError(path.string(), "no *VERTICES section");
  if (m < 0)
    throw InputError(path.string(), "no *ELEMENTS section");
  for (std::size_t i = 0; i < idx.size(); ++i)
    if (idx[i] >= n)
      throw InputError(path.string() + ":" + std::to_string(lines.tet_lines[i / 4]),
          "element " + std::to_string(i / 4 + 1) + " has vertex id " + std::to_string(idx[i] + 1)
              + " out of range [1, " + std::to_string(n) + "]");
  Positions rest = Eigen::Map<const Positions>(xyz.data(), static_cast<Eigen::Index>(n), 3);
  Tets tets = Eigen::Map<const Tets>(idx.data(), static_cast<Eigen::Index>(m), 4);
  validate_tet_mesh(rest, tets, path.string(), &lines);
  return TetMesh(std::move(rest), std::move(tets), path.string());
}

} // namespace elastolearn::mesh
