#pragma once
/// \file VTK XML UnstructuredGrid (.vtu) files for ParaView, one per frame, plus the .pvd
/// collection that indexes them by time (`write_vtu_series` is declared in trajectory_file.hpp).
/// Format: VTKFile version 1.0, header_type UInt64, native byte order, every DataArray inline
/// "binary" = base64 of (UInt64 byte count + raw values) in one stream, as VTK itself writes it.
#include <elastolearn/core/types.hpp>
#include <elastolearn/io/trajectory_file.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn::io {

/// VTK cell type codes used here.
enum class VtkCellType : unsigned char { vertex = 1, line = 3, triangle = 5, tetra = 10 };

/// The cells of a VTU piece, all of one type, encoded once (connectivity, offsets, types) so that
/// a series of frames reuses the same bytes. Converts implicitly from Tets, Faces and Edges.
class VtuCells {
  public:
  VtuCells(const Tets& tets); ///< VTK_TETRA (10)
  VtuCells(const Faces& faces); ///< VTK_TRIANGLE (5)
  VtuCells(const Edges& edges); ///< VTK_LINE (3)
  /// One VTK_VERTEX (1) per point: a point cloud or a mesh without elements.
  static VtuCells vertices(Eigen::Index points);
  /// Tets if any, else faces, else edges, else one vertex cell per rest vertex.
  static VtuCells of(const TrajectoryData& data);

  Eigen::Index size() const { return m_count; }
  VtkCellType type() const { return m_type; }
  /// Largest vertex index referenced (-1 if none).
  int max_index() const { return m_max_index; }
  /// The encoded `<Cells>` element.
  const std::string& xml() const { return m_xml; }

  private:
  VtuCells(const int* connectivity, Eigen::Index count, int nodes, VtkCellType type);
  Eigen::Index m_count = 0;
  VtkCellType m_type = VtkCellType::vertex;
  int m_max_index = -1;
  std::string m_xml;
};

/// A named per-point vector field (n×3) written as VTK point data.
struct VtuField {
  std::string name;
  Eigen::Ref<const Positions> values;
};

/// Write one .vtu atomically: points `positions` (n×3 [m]), `cells`, and `point_data` (each n×3).
/// Throws InputError naming `path` if a field has the wrong row count, a cell references a
/// missing point, or the file cannot be written.
void write_vtu(const std::filesystem::path& path, ConstRef<Positions> positions,
    const VtuCells& cells, const std::vector<VtuField>& point_data = {});

/// Write a .pvd collection atomically: one DataSet per (time, file); files are written relative to
/// the .pvd's directory when they lie under it.
void write_pvd(const std::filesystem::path& path, const std::vector<double>& times,
    const std::vector<std::filesystem::path>& files);

/// Standard base64 (RFC 4648, with '=' padding) of `bytes`, appended to `out`.
void append_base64(std::string& out, const void* bytes, std::size_t size);

} // namespace elastolearn::io
