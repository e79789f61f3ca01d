#pragma once
/// \file Crash-safe output: write to a temporary file beside the target, rename on success.
/// A failed run (exception, divergence, Ctrl-C) never leaves a half-written output behind.
#include <filesystem>
#include <string>

namespace elastolearn {

/// Owns a temporary path `<target>.tmp-<pid>`; `commit()` renames it onto the target.
/// If destroyed without commit (e.g. during stack unwinding) the temporary file is removed.
class AtomicFile {
  public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Where to write now.
  const std::filesystem::path& temp_path() const { return m_temp; }
  /// Final destination.
  const std::filesystem::path& target() const { return m_target; }
  /// Atomically move the temporary file onto the target. Throws InputError if it cannot.
  void commit();

  private:
  std::filesystem::path m_target;
  std::filesystem::path m_temp;
  bool m_committed = false;
};

/// Write a whole text file atomically. Throws InputError naming the path on failure.
void write_text_file_atomic(const std::filesystem::path& path, const std::string& contents);

/// Read a whole text file. Throws InputError naming the path if it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

} // namespace elastolearn
