#pragma once
/// \file Stanford PLY files, ASCII and binary little-endian: the header (elements and their
/// properties) and a cursor over the body. One reader serves the surface meshes
/// (read_surface_mesh) and the point clouds (io/point_cloud_file.hpp); each caller walks the
/// elements it knows and skips the rest. Errors are InputError naming "file:line" (ASCII) or the
/// file and the element record (binary).
#include <elastolearn/mesh/line_reader.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn::mesh {

/// Storage type of a PLY property (char/int8 … double/float64).
enum class PlyType { i8, u8, i16, u16, i32, u32, f32, f64 };

struct PlyProperty {
  std::string name;
  bool list = false; ///< a list property: a count of `count_type`, then that many `type` values
  PlyType count_type = PlyType::u8;
  PlyType type = PlyType::f32;
};

struct PlyElement {
  std::string name;
  long long count = 0; ///< number of records, < 2³¹
  std::vector<PlyProperty> props;
};

/// A PLY file read whole, its header parsed on construction; the body is then read record by
/// record, in file order: for each element, for each of its `count` records, begin_record()
/// and then one value() (or skip()) per property.
class PlyReader {
  public:
  /// Reads `path` and parses the header. Throws InputError for a missing 'ply' magic, an
  /// unsupported format (big-endian), an unknown type, a bad count or a missing end_header.
  explicit PlyReader(const std::filesystem::path& path);

  const std::vector<PlyElement>& elements() const { return m_elements; }
  bool binary() const { return m_binary; }
  const std::string& name() const { return m_in.name(); }

  /// Start the next record; `what` names it in errors ("vertex 3 of 10"). In ASCII files a
  /// record is one line.
  void begin_record(const std::string& what);
  /// The next value of the current record, converted to double. Throws InputError when the
  /// record or the file ends early or (ASCII) a token is not a number. NaN/inf are returned as
  /// they are: the caller decides whether they are allowed.
  double value(PlyType type);
  /// Read and discard property `p` of the current record (a list: its count, then its values).
  void skip(const PlyProperty& p);
  /// The place of the current record for error messages: "file:line" (ASCII) or "file".
  std::string where() const;

  private:
  template <int N, typename U> U bytes();

  LineReader m_in;
  bool m_binary = false;
  std::vector<PlyElement> m_elements;
  std::size_t m_pos = 0; ///< binary read position
  std::size_t m_token = 0; ///< ASCII token within the current line
  std::string m_what;
};

} // namespace elastolearn::mesh
