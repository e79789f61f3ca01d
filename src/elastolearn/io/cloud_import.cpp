#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/cloud_import.hpp>
#include <elastolearn/mesh/line_reader.hpp>
#include <elastolearn/mesh/ply_reader.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>

namespace elastolearn::io {

namespace {

/// Growing columns of a frame; turned into a CloudFrame at the end (no allocation from a count
/// a file merely claims).
struct FrameBuilder {
  std::vector<double> points, normals, confidence;

  capture::CloudFrame finish() const {
    capture::CloudFrame frame;
    const Eigen::Index n = static_cast<Eigen::Index>(points.size() / 3);
    frame.points = Eigen::Map<const Positions>(points.data(), n, 3);
    if (!normals.empty())
      frame.normals = Eigen::Map<const Positions>(normals.data(), n, 3);
    if (!confidence.empty())
      frame.confidence = Eigen::Map<const VecX>(confidence.data(), n);
    return frame;
  }
};

/// Checks shared by both formats; `where` names file (and line or record).
void check_values(
    const std::string& where, const double* xyz, const double* normal, const double* confidence) {
  static const char* axis[3] = { "x", "y", "z" };
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(xyz[c]))
      throw InputError(
          where, "non-finite " + std::string(axis[c]) + " coordinate " + to_text(xyz[c]));
  if (normal) {
    const double length
        = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    if (!(std::abs(length - 1) <= capture::k_normal_length_tolerance))
      throw InputError(where,
          "normal (" + to_text(normal[0]) + ", " + to_text(normal[1]) + ", " + to_text(normal[2])
              + ") is not a unit vector (length " + to_text(length) + ")");
  }
  if (confidence && !(*confidence >= 0 && *confidence <= 1))
    throw InputError(where, "confidence " + to_text(*confidence) + " is not in [0, 1]");
}

capture::CloudFrame read_xyz(const std::filesystem::path& path) {
  mesh::LineReader in(path, '#');
  in.split_on_commas(true);
  FrameBuilder frame;
  std::size_t columns = 0;
  while (in.next()) {
    if (columns == 0) {
      columns = in.size();
      if (columns != 3 && columns != 4 && columns != 6 && columns != 7)
        in.fail("expected 3 (x y z), 4 (x y z confidence), 6 (x y z nx ny nz) or 7 columns, found "
            + std::to_string(columns));
    } else if (in.size() != columns) {
      in.fail("has " + std::to_string(in.size()) + " columns, the first point's line has "
          + std::to_string(columns));
    }
    double v[7];
    for (std::size_t i = 0; i < columns; ++i)
      if (!mesh::parse_real(in[i], v[i]))
        in.fail(
            "column " + std::to_string(i + 1) + ": '" + std::string(in[i]) + "' is not a number");
    const bool has_normal = columns >= 6;
    const bool has_confidence = columns == 4 || columns == 7;
    const double* confidence = has_confidence ? &v[columns - 1] : nullptr;
    check_values(in.where(), v, has_normal ? v + 3 : nullptr, confidence);
    frame.points.insert(frame.points.end(), v, v + 3);
    if (has_normal)
      frame.normals.insert(frame.normals.end(), v + 3, v + 6);
    if (confidence)
      frame.confidence.push_back(*confidence);
  }
  return frame.finish();
}

capture::CloudFrame read_ply_cloud(const std::filesystem::path& path) {
  mesh::PlyReader ply(path);
  FrameBuilder frame;
  bool have_vertex = false;
  for (const mesh::PlyElement& e : ply.elements()) {
    const bool is_vertex = e.name == "vertex";
    if (is_vertex && have_vertex)
      throw InputError(path.string(), "PLY file has two vertex elements");
    // Column of each property in [x, y, z, nx, ny, nz, confidence], −1 for others.
    std::vector<int> slot(e.props.size(), -1);
    int found = 0;
    if (is_vertex) {
      have_vertex = true;
      static const char* names[7] = { "x", "y", "z", "nx", "ny", "nz", "confidence" };
      for (std::size_t p = 0; p < e.props.size(); ++p)
        for (int k = 0; k < 7; ++k)
          if (!e.props[p].list && e.props[p].name == names[k]) {
            slot[p] = k;
            found |= 1 << k;
          }
      if ((found & 7) != 7)
        throw InputError(path.string(), "PLY vertex element lacks x, y or z");
      const int normal_bits = (found >> 3) & 7;
      if (normal_bits != 0 && normal_bits != 7)
        throw InputError(path.string(), "PLY vertex element has some of nx, ny, nz but not all");
    }
    const bool has_normal = (found & (7 << 3)) != 0;
    const bool has_confidence = (found & (1 << 6)) != 0;
    for (long long i = 0; i < e.count; ++i) {
      const std::string what = e.name + " " + std::to_string(i) + " of " + std::to_string(e.count);
      ply.begin_record(what);
      double v[7] = { 0, 0, 0, 0, 0, 0, 0 };
      for (std::size_t p = 0; p < e.props.size(); ++p) {
        if (slot[p] < 0)
          ply.skip(e.props[p]);
        else
          v[slot[p]] = ply.value(e.props[p].type);
      }
      if (!is_vertex)
        continue;
      const std::string where = ply.binary() ? path.string() + ": " + what : ply.where();
      check_values(where, v, has_normal ? v + 3 : nullptr, has_confidence ? v + 6 : nullptr);
      frame.points.insert(frame.points.end(), v, v + 3);
      if (has_normal)
        frame.normals.insert(frame.normals.end(), v + 3, v + 6);
      if (has_confidence)
        frame.confidence.push_back(v[6]);
    }
  }
  if (!have_vertex)
    throw InputError(path.string(), "PLY file has no vertex element");
  return frame.finish();
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

} // namespace

capture::CloudFrame read_point_cloud_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply")
    return read_ply_cloud(path);
  if (ext == ".xyz")
    return read_xyz(path);
  throw InputError(path.string(), "unknown point-cloud extension '" + ext + "' (.ply or .xyz)");
}

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  int zeros_tie = 0; // first difference in leading zeros: more zeros first
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      std::size_t i0 = i, j0 = j;
      while (i0 < a.size() && a[i0] == '0')
        ++i0;
      while (j0 < b.size() && b[j0] == '0')
        ++j0;
      std::size_t i1 = i0, j1 = j0;
      while (i1 < a.size() && is_digit(a[i1]))
        ++i1;
      while (j1 < b.size() && is_digit(b[j1]))
        ++j1;
      // Without leading zeros, the longer digit run is the larger number.
      if (i1 - i0 != j1 - j0)
        return i1 - i0 < j1 - j0;
      const int c = a.compare(i0, i1 - i0, b, j0, j1 - j0);
      if (c != 0)
        return c < 0;
      if (zeros_tie == 0 && i0 - i != j0 - j)
        zeros_tie = (i0 - i > j0 - j) ? -1 : 1;
      i = i1;
      j = j1;
    } else {
      if (a[i] != b[j])
        return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
      ++i;
      ++j;
    }
  }
  if (i < a.size() || j < b.size())
    return j < b.size(); // a is a prefix of b
  return zeros_tie < 0;
}

std::vector<std::filesystem::path> list_point_cloud_files(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::exists(folder, ec))
    throw InputError(folder.string(), "no such folder");
  if (!std::filesystem::is_directory(folder, ec))
    throw InputError(
        folder.string(), "not a folder (give the folder that holds one file per frame)");
  std::vector<std::filesystem::path> files;
  std::filesystem::directory_iterator it(folder, ec);
  if (ec)
    throw InputError(folder.string(), "cannot list the folder: " + ec.message());
  for (const auto& entry : it) {
    const std::string ext = lower_extension(entry.path());
    if ((ext == ".ply" || ext == ".xyz") && !entry.is_directory(ec))
      files.push_back(entry.path());
  }
  if (files.empty())
    throw InputError(folder.string(), "no .ply or .xyz files in the folder");
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return files;
}

void read_point_cloud_folder(const std::filesystem::path& folder,
    const std::function<void(const std::filesystem::path& file, const capture::CloudFrame& frame)>&
        sink) {
  capture::FrameLayout layout;
  for (const auto& file : list_point_cloud_files(folder)) {
    const capture::CloudFrame frame = read_point_cloud_file(file);
    layout.check(frame, file.string());
    sink(file, frame);
  }
}

capture::PointCloudSequence import_point_clouds(
    const std::filesystem::path& folder, double dt, double start_time) {
  if (!std::isfinite(dt) || dt <= 0)
    throw InputError("dt", "the time between frames must be positive, got " + to_text(dt));
  std::vector<capture::CloudFrame> frames;
  read_point_cloud_folder(folder,
      [&](const std::filesystem::path&, const capture::CloudFrame& f) { frames.push_back(f); });
  return capture::PointCloudSequence::from_frames(frames, dt, start_time, folder.string());
}

} // namespace elastolearn::io
