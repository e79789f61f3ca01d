#pragma once
// Helpers shared by the mesh tests: a per-test temporary directory, fixtures, and an assertion
// that a call throws InputError whose message contains given fragments.
#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace elastolearn::test {

/// A fresh directory under the system temp dir, removed at the end of the test.
class TempDir {
  public:
  TempDir() {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("elastolearn_mesh_") + std::to_string(::getpid()) + "_"
        + (info ? std::string(info->test_suite_name()) + "_" + info->name() : "x");
    for (char& c : name)
      if (c == '/')
        c = '_';
    m_path = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(m_path, ec);
  }
  const std::filesystem::path& path() const { return m_path; }
  std::filesystem::path operator/(const std::string& name) const { return m_path / name; }

  private:
  std::filesystem::path m_path;
};

inline std::filesystem::path fixture(const std::string& name) {
  return std::filesystem::path(ELASTOLEARN_TEST_DATA_DIR) / "mesh" / name;
}

inline std::string read_fixture(const std::string& name) {
  return read_text_file(fixture(name));
}

inline void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// `text` with the first occurrence of `from` replaced (fails the test if absent).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "fixture lacks '" << from << "'";
  if (pos != std::string::npos)
    text.replace(pos, from.size(), to);
  return text;
}

/// Runs f, expects InputError whose message contains every fragment.
template <typename F> void expect_input_error(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& frag : fragments)
      EXPECT_NE(msg.find(frag), std::string::npos)
          << "message '" << msg << "' lacks '" << frag << "'";
  }
}

/// Σ over outward faces of (area·n)·centroid/3 — the divergence theorem with F(x) = x/3 gives the
/// enclosed volume exactly for a closed, outward oriented triangle surface.
inline double divergence_volume(const Positions& x, const Faces& f) {
  double v = 0;
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    const Vec3 a = x.row(f(i, 0)), b = x.row(f(i, 1)), c = x.row(f(i, 2));
    const Vec3 area_normal = 0.5 * (b - a).cross(c - a);
    v += area_normal.dot((a + b + c) / 3.0) / 3.0;
  }
  return v;
}

inline double surface_area(const Positions& x, const Faces& f) {
  double s = 0;
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    const Vec3 a = x.row(f(i, 0)), b = x.row(f(i, 1)), c = x.row(f(i, 2));
    s += 0.5 * (b - a).cross(c - a).norm();
  }
  return s;
}

} // namespace elastolearn::test
