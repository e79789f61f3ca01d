#pragma once
/// \file Run the built `elastolearn` executable (ELASTOLEARN_EXECUTABLE) with arguments and
/// capture its exit code and output, and give each end-to-end CLI test its own folder.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace elastolearn::test {

struct Run {
  int exit_code;
  std::string output; ///< stdout + stderr
};

/// What one run printed on each stream, and how it ended.
struct SplitRun {
  int exit_code; ///< the exit status, or 128 + signal if a signal ended it (as a shell reports)
  std::string out; ///< stdout
  std::string err; ///< stderr
};

/// Run `elastolearn arguments` through the shell with stdout and stderr captured apart. `prefix`
/// is shell text run first in the same shell (e.g. "cd DIR && ulimit -v N &&").
inline SplitRun run_split(const std::string& arguments, const std::string& prefix = "") {
  static int counter = 0;
  const std::filesystem::path err_file = std::filesystem::temp_directory_path()
      / ("elastolearn_stderr_" + std::to_string(::getpid()) + "_" + std::to_string(++counter));
  const std::string command = prefix + " " + std::string(ELASTOLEARN_EXECUTABLE) + " " + arguments
      + " 2>'" + err_file.string() + "'";
  FILE* pipe = popen(command.c_str(), "r");
  SplitRun r { -1, "", "" };
  std::array<char, 4096> buffer {};
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe))
    r.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(err_file, std::ios::binary);
  r.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  in.close();
  std::filesystem::remove(err_file);
  return r;
}

inline Run run(const std::string& arguments) {
  const std::string command = std::string(ELASTOLEARN_EXECUTABLE) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  Run r { -1, "" };
  std::array<char, 4096> buffer {};
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe))
    r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// Fixture base: a fresh temporary folder per test (suite, test and process in its name, so
/// parallel ctest runs never share one), removed afterwards.
class CliTestFolder : public ::testing::Test {
  protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_dir = std::filesystem::temp_directory_path()
        / ("elastolearn_" + std::string(info->test_suite_name()) + "_" + info->name() + "_"
            + std::to_string(::getpid()));
    std::filesystem::remove_all(m_dir);
    std::filesystem::create_directories(m_dir);
  }
  void TearDown() override { std::filesystem::remove_all(m_dir); }
  /// Write `text` to `name` in the folder; returns its path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(m_dir / name) << text;
    return m_dir / name;
  }
  std::filesystem::path m_dir;
};

} // namespace elastolearn::test
