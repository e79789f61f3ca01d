#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/vtu_writer.hpp>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <numeric>

namespace elastolearn::io {

namespace {

constexpr char k_alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

const char* byte_order() {
  return std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
}

/// One inline binary DataArray: base64 of the UInt64 byte count followed by the raw values, as a
/// single stream (8 header bytes + the first data byte make 9 = 3×3 bytes, so the two parts can
/// be encoded separately without padding in between).
void append_data_array(std::string& out, const char* type, const std::string& name, int components,
    const void* values, std::size_t bytes) {
  out += "        <DataArray type=\"";
  out += type;
  out += "\" Name=\"" + html_escape(name) + "\"";
  if (components > 1)
    out += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  out += " format=\"binary\">\n          ";
  unsigned char head[9];
  const std::uint64_t count = bytes;
  std::memcpy(head, &count, 8);
  if (bytes == 0) {
    append_base64(out, head, 8);
  } else {
    const auto* data = static_cast<const unsigned char*>(values);
    head[8] = data[0];
    append_base64(out, head, 9);
    append_base64(out, data + 1, bytes - 1);
  }
  out += "\n        </DataArray>\n";
}

void append_positions(
    std::string& out, const std::string& name, ConstRef<Positions> x, Positions& scratch) {
  const double* data = x.data();
  if (x.rows() > 0 && x.outerStride() != 3) {
    scratch = x;
    data = scratch.data();
  }
  append_data_array(out, "Float64", name, 3, data, std::size_t(x.rows()) * 3 * sizeof(double));
}

std::string shortest(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

} // namespace

void append_base64(std::string& out, const void* bytes, std::size_t size) {
  const auto* in = static_cast<const unsigned char*>(bytes);
  const std::size_t start = out.size();
  out.resize(start + (size + 2) / 3 * 4);
  char* o = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= size; i += 3, o += 4) {
    const std::uint32_t v
        = (std::uint32_t(in[i]) << 16) | (std::uint32_t(in[i + 1]) << 8) | in[i + 2];
    o[0] = k_alphabet[(v >> 18) & 63];
    o[1] = k_alphabet[(v >> 12) & 63];
    o[2] = k_alphabet[(v >> 6) & 63];
    o[3] = k_alphabet[v & 63];
  }
  if (i < size) {
    const std::uint32_t v
        = (std::uint32_t(in[i]) << 16) | (i + 1 < size ? std::uint32_t(in[i + 1]) << 8 : 0);
    o[0] = k_alphabet[(v >> 18) & 63];
    o[1] = k_alphabet[(v >> 12) & 63];
    o[2] = i + 1 < size ? k_alphabet[(v >> 6) & 63] : '=';
    o[3] = '=';
  }
}

// --- VtuCells --------------------------------------------------------------------------------

VtuCells::VtuCells(const int* connectivity, Eigen::Index count, int nodes, VtkCellType type)
    : m_count(count)
    , m_type(type) {
  const std::size_t values = std::size_t(count) * nodes;
  if (values > 0)
    m_max_index = *std::max_element(connectivity, connectivity + values);
  std::vector<std::int64_t> offsets(count);
  for (Eigen::Index c = 0; c < count; ++c)
    offsets[c] = std::int64_t(c + 1) * nodes;
  const std::vector<std::uint8_t> types(count, static_cast<std::uint8_t>(type));
  m_xml = "      <Cells>\n";
  append_data_array(m_xml, "Int32", "connectivity", 1, connectivity, values * sizeof(int));
  append_data_array(m_xml, "Int64", "offsets", 1, offsets.data(), offsets.size() * 8);
  append_data_array(m_xml, "UInt8", "types", 1, types.data(), types.size());
  m_xml += "      </Cells>\n";
}

VtuCells::VtuCells(const Tets& tets)
    : VtuCells(tets.data(), tets.rows(), 4, VtkCellType::tetra) { }
VtuCells::VtuCells(const Faces& faces)
    : VtuCells(faces.data(), faces.rows(), 3, VtkCellType::triangle) { }
VtuCells::VtuCells(const Edges& edges)
    : VtuCells(edges.data(), edges.rows(), 2, VtkCellType::line) { }

VtuCells VtuCells::vertices(Eigen::Index points) {
  std::vector<int> ids(points);
  std::iota(ids.begin(), ids.end(), 0);
  return VtuCells(ids.data(), points, 1, VtkCellType::vertex);
}

VtuCells VtuCells::of(const TrajectoryData& data) {
  if (data.tets.rows() > 0)
    return VtuCells(data.tets);
  if (data.faces.rows() > 0)
    return VtuCells(data.faces);
  if (data.edges.rows() > 0)
    return VtuCells(data.edges);
  return vertices(data.rest_positions.rows());
}

// --- files -----------------------------------------------------------------------------------

void write_vtu(const std::filesystem::path& path, ConstRef<Positions> positions,
    const VtuCells& cells, const std::vector<VtuField>& point_data) {
  const std::string name = path.string();
  const Eigen::Index n = positions.rows();
  if (cells.max_index() >= n) {
    throw InputError(name,
        "a cell references vertex " + std::to_string(cells.max_index()) + " but there are only "
            + std::to_string(n) + " points");
  }
  for (const VtuField& field : point_data) {
    if (field.values.rows() != n) {
      throw InputError(name,
          "point data '" + field.name + "' has " + std::to_string(field.values.rows())
              + " rows, expected " + std::to_string(n));
    }
  }
  std::string out;
  out.reserve(std::size_t(n) * 3 * 8 * (point_data.size() + 1) * 4 / 3 + cells.xml().size() + 1024);
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
         "byte_order=\"";
  out += byte_order();
  out += "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\""
      + std::to_string(n) + "\" NumberOfCells=\"" + std::to_string(cells.size()) + "\">\n";
  Positions scratch;
  if (!point_data.empty()) {
    out += "      <PointData Vectors=\"" + html_escape(point_data.front().name) + "\">\n";
    for (const VtuField& field : point_data)
      append_positions(out, field.name, field.values, scratch);
    out += "      </PointData>\n";
  }
  out += "      <Points>\n";
  append_positions(out, "Points", positions, scratch);
  out += "      </Points>\n";
  out += cells.xml();
  out += "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  write_text_file_atomic(path, out);
}

void write_pvd(const std::filesystem::path& path, const std::vector<double>& times,
    const std::vector<std::filesystem::path>& files) {
  if (times.size() != files.size()) {
    throw InputError(path.string(),
        std::to_string(times.size()) + " times for " + std::to_string(files.size()) + " files");
  }
  const std::filesystem::path base = path.parent_path();
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" "
                    "byte_order=\"";
  out += byte_order();
  out += "\" header_type=\"UInt64\">\n  <Collection>\n";
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::filesystem::path& f = files[i];
    const std::string file
        = f.parent_path() == base ? f.filename().generic_string() : f.generic_string();
    out += "    <DataSet timestep=\"" + shortest(times[i]) + "\" group=\"\" part=\"0\" file=\""
        + html_escape(file) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  write_text_file_atomic(path, out);
}

std::filesystem::path write_vtu_series(
    const std::filesystem::path& directory, const std::string& stem, const TrajectoryData& data) {
  const std::string where = (directory / stem).string();
  const std::size_t frames = data.positions.size();
  const Eigen::Index n = data.rest_positions.rows();
  if (data.time.size() != frames) {
    throw InputError(where,
        std::to_string(frames) + " position frames but " + std::to_string(data.time.size())
            + " times");
  }
  if (!data.velocities.empty() && data.velocities.size() != frames) {
    throw InputError(where,
        std::to_string(frames) + " position frames but " + std::to_string(data.velocities.size())
            + " velocity frames");
  }
  const VtuCells cells = VtuCells::of(data);
  const std::size_t width
      = std::max<std::size_t>(4, std::to_string(frames ? frames - 1 : 0).size());
  std::vector<std::filesystem::path> files;
  files.reserve(frames);
  Positions displacement(n, 3);
  for (std::size_t t = 0; t < frames; ++t) {
    const Positions& x = data.positions[t];
    if (x.rows() != n) {
      throw InputError(where,
          "frame " + std::to_string(t) + " has " + std::to_string(x.rows()) + " vertices, expected "
              + std::to_string(n));
    }
    displacement = x - data.rest_positions;
    std::vector<VtuField> fields { { "displacement", displacement } };
    if (!data.velocities.empty())
      fields.push_back({ "velocity", data.velocities[t] });
    std::string number = std::to_string(t);
    number.insert(0, width - number.size(), '0');
    files.push_back(directory / (stem + "_" + number + ".vtu"));
    write_vtu(files.back(), x, cells, fields);
  }
  const std::filesystem::path pvd = directory / (stem + ".pvd");
  write_pvd(pvd, data.time, files);
  return pvd;
}

} // namespace elastolearn::io
