#include <elastolearn/mesh/gmsh_io.hpp>

#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/mesh_validation.hpp>

#include <unordered_map>

namespace elastolearn::mesh {

namespace {

constexpr long long kTet4 = 4;

struct Node {
  Vec3 x;
  int line;
};

struct RawTet {
  std::array<long long, 4> tags;
  int line;
};

class GmshParser {
  public:
  explicit GmshParser(const std::filesystem::path& path)
      : m_in(path, '\0')
      , m_path(path) { }

  TetMesh parse() {
    bool have_format = false;
    while (m_in.next()) {
      const std::string_view section = m_in[0];
      if (section == "$MeshFormat") {
        read_format();
        have_format = true;
      } else if (section == "$Nodes") {
        if (!have_format)
          m_in.fail("$Nodes before $MeshFormat");
        m_v4 ? read_nodes_v4() : read_nodes_v2();
        end_section("$EndNodes");
      } else if (section == "$Elements") {
        if (!have_format)
          m_in.fail("$Elements before $MeshFormat");
        m_v4 ? read_elements_v4() : read_elements_v2();
        end_section("$EndElements");
      } else if (section.starts_with("$") && !section.starts_with("$End")) {
        skip_section(std::string("$End") + std::string(section.substr(1)));
      } else {
        m_in.fail("unexpected line '" + std::string(m_in.line()) + "' outside a section");
      }
    }
    if (!have_format)
      throw InputError(m_path.string(), "no $MeshFormat section (not a Gmsh file?)");
    return build();
  }

  private:
  void read_format() {
    m_in.require("the $MeshFormat line");
    const double version = m_in.real(0, "format version");
    const long long file_type = m_in.integer(1, "file type");
    if (file_type != 0)
      m_in.fail("binary .msh files are not supported; save as ASCII");
    if (version >= 2.0 && version < 3.0)
      m_v4 = false;
    else if (version >= 4.1 && version < 5.0)
      m_v4 = true;
    else
      m_in.fail("unsupported .msh version " + std::string(m_in[0]) + " (use 2.2 or 4.1)");
    end_section("$EndMeshFormat");
  }

  void end_section(const std::string& end) {
    m_in.require(end);
    if (m_in[0] != end)
      m_in.fail("expected " + end + ", got '" + std::string(m_in.line()) + "'");
  }

  void skip_section(const std::string& end) {
    do
      m_in.require(end);
    while (m_in[0] != end);
  }

  long long count(std::size_t i, const char* what) {
    const long long n = m_in.integer(i, what);
    if (n < 0 || n >= (1LL << 31))
      m_in.fail(std::string("invalid ") + what + " " + std::to_string(n));
    return n;
  }

  void add_node(long long tag, const Vec3& x) {
    if (!m_index.emplace(tag, static_cast<int>(m_nodes.size())).second)
      m_in.fail("duplicate node tag " + std::to_string(tag));
    m_nodes.push_back({ x, m_in.line_number() });
  }

  Vec3 coords(std::size_t first) {
    return { m_in.real(first, "x coordinate"), m_in.real(first + 1, "y coordinate"),
      m_in.real(first + 2, "z coordinate") };
  }

  void read_nodes_v2() {
    m_in.require("the number of nodes");
    const long long n = count(0, "number of nodes");
    for (long long i = 0; i < n; ++i) {
      m_in.require("node " + std::to_string(i + 1) + " of " + std::to_string(n));
      m_in.require_tokens(4, "a node");
      add_node(m_in.integer(0, "node tag"), coords(1));
    }
  }

  void read_nodes_v4() {
    m_in.require("the $Nodes header");
    m_in.require_tokens(2, "the $Nodes header");
    const long long blocks = count(0, "number of entity blocks");
    for (long long b = 0; b < blocks; ++b) {
      m_in.require("a node entity block header");
      m_in.require_tokens(4, "a node entity block header");
      const long long n = count(3, "number of nodes in block");
      std::vector<long long> tags;
      for (long long i = 0; i < n; ++i) {
        m_in.require("a node tag");
        tags.push_back(m_in.integer(0, "node tag"));
      }
      for (long long i = 0; i < n; ++i) {
        m_in.require("node coordinates");
        m_in.require_tokens(3, "node coordinates");
        add_node(tags[static_cast<std::size_t>(i)], coords(0));
      }
    }
  }

  void add_tet(std::size_t first) {
    RawTet t { {}, m_in.line_number() };
    for (std::size_t k = 0; k < 4; ++k)
      t.tags[k] = m_in.integer(first + k, "node tag");
    m_tets.push_back(t);
  }

  void read_elements_v2() {
    m_in.require("the number of elements");
    const long long n = count(0, "number of elements");
    for (long long i = 0; i < n; ++i) {
      m_in.require("element " + std::to_string(i + 1) + " of " + std::to_string(n));
      m_in.require_tokens(3, "an element");
      if (m_in.integer(1, "element type") != kTet4)
        continue;
      const long long ntags = count(2, "number of element tags");
      m_in.require_tokens(static_cast<std::size_t>(3 + ntags + 4), "a tetrahedron");
      add_tet(static_cast<std::size_t>(3 + ntags));
    }
  }

  void read_elements_v4() {
    m_in.require("the $Elements header");
    m_in.require_tokens(2, "the $Elements header");
    const long long blocks = count(0, "number of entity blocks");
    for (long long b = 0; b < blocks; ++b) {
      m_in.require("an element entity block header");
      m_in.require_tokens(4, "an element entity block header");
      const bool tets = m_in.integer(2, "element type") == kTet4;
      const long long n = count(3, "number of elements in block");
      for (long long i = 0; i < n; ++i) {
        m_in.require("an element");
        if (!tets)
          continue;
        m_in.require_tokens(5, "a tetrahedron");
        add_tet(1);
      }
    }
  }

  TetMesh build() {
    if (m_tets.empty())
      throw InputError(m_path.string(), "no tetrahedra (element type 4) found");
    // Keep only nodes used by some tet, in file order.
    std::vector<int> slot_of_tet_vertex;
    slot_of_tet_vertex.reserve(m_tets.size() * 4);
    for (const RawTet& t : m_tets)
      for (long long tag : t.tags) {
        const auto it = m_index.find(tag);
        if (it == m_index.end())
          throw InputError(m_path.string() + ":" + std::to_string(t.line),
              "tetrahedron refers to unknown node tag " + std::to_string(tag));
        slot_of_tet_vertex.push_back(it->second);
      }
    std::vector<int> compact(m_nodes.size(), -1);
    for (int s : slot_of_tet_vertex)
      compact[static_cast<std::size_t>(s)] = 0;
    SourceLines lines;
    int n = 0;
    for (std::size_t s = 0; s < m_nodes.size(); ++s)
      if (compact[s] == 0) {
        compact[s] = n++;
        lines.vertex_lines.push_back(m_nodes[s].line);
      }
    Positions rest(n, 3);
    for (std::size_t s = 0; s < m_nodes.size(); ++s)
      if (compact[s] >= 0)
        rest.row(compact[s]) = m_nodes[s].x;
    Tets tets(static_cast<Eigen::Index>(m_tets.size()), 4);
    for (std::size_t t = 0; t < m_tets.size(); ++t) {
      for (int k = 0; k < 4; ++k)
        tets(static_cast<Eigen::Index>(t), k)
            = compact[static_cast<std::size_t>(slot_of_tet_vertex[4 * t + k])];
      lines.tet_lines.push_back(m_tets[t].line);
    }
    validate_tet_mesh(rest, tets, m_path.string(), &lines);
    return TetMesh(std::move(rest), std::move(tets), m_path.string());
  }

  LineReader m_in;
  std::filesystem::path m_path;
  bool m_v4 = false;
  std::vector<Node> m_nodes;
  std::unordered_map<long long, int> m_index;
  std::vector<RawTet> m_tets;
};

} // namespace

TetMesh read_gmsh(const std::filesystem::path& path) {
  return GmshParser(path).parse();
}

} // namespace elastolearn::mesh
