#pragma once
/// \file Running an external program (TetGen) without a shell: posix_spawn with an argument
/// vector, so file names are never interpreted by a shell.
#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn::mesh {

/// How a program run ended.
struct ProgramResult {
  int exit_code = -1; ///< exit status, or -1 if killed by a signal
  int signal = 0; ///< terminating signal, 0 if it exited
  std::string output; ///< its stdout and stderr, interleaved (last 64 KiB)
  bool ok() const { return signal == 0 && exit_code == 0; }
};

/// Runs `program` with `args` (argv[1..]), stdout+stderr captured through `log_file`, waits for it.
/// Throws InputError naming the program if it cannot be started.
ProgramResult run_program(const std::filesystem::path& program,
    const std::vector<std::string>& args, const std::filesystem::path& log_file);

/// A fresh private directory under the system temp dir, removed with its contents on destruction.
class TemporaryDirectory {
  public:
  explicit TemporaryDirectory(const std::string& prefix);
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::filesystem::path& path() const { return m_path; }

  private:
  std::filesystem::path m_path;
};

} // namespace elastolearn::mesh
