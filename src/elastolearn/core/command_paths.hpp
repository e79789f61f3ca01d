#pragma once
/// \file The files a command reads and writes, checked before it does any work: no output may be
/// one of the inputs (writing it would replace the user's data), no two outputs may be the same
/// file, and every output must be creatable (its folder exists or can be made, and is writable).
/// Every command of the app lists its files and calls check_command_paths() once.
#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn {

/// A file a command reads, and what it is, for messages: {"traj.h5", "trajectory"}.
struct CommandInput {
  std::filesystem::path path;
  std::string role; ///< "trajectory", "scene", "mesh of the scene", ...
};

/// What an output path is: a file (written beside it and renamed onto it) or a folder that
/// files are written into (created if missing).
enum class OutputKind { file, folder };

/// A file or folder a command writes, and what it is, for messages: {"obs.h5", "output (-o)"}.
struct CommandOutput {
  std::filesystem::path path;
  std::string role; ///< "output (-o)", "--report folder", ...
  OutputKind kind = OutputKind::file;
};

/// True if `a` and `b` name the same file. When both exist this is file identity
/// (std::filesystem::equivalent: same device and inode), so different spellings ("./a.h5" and
/// "a.h5"), symbolic links and hard links are all caught. When neither exists, their absolute,
/// lexically normalised paths with every existing symbolic link resolved are compared. When only
/// one exists they are different files.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

/// Check a command's files before it reads or writes anything else. Throws InputError naming the
/// output path (one line) if
/// - an output path is empty, or is the same file as an input (same_file);
/// - two outputs are the same file;
/// - an output exists as the wrong kind (a folder where a file is written, or the reverse);
/// - an output cannot be created: the nearest existing ancestor of its folder is not a folder,
///   or is not writable by this process.
/// Checking creatability here is an early, clear diagnosis; the writers still report (and clean
/// up after) any failure that happens later, e.g. a full disk.
void check_command_paths(
    const std::vector<CommandInput>& inputs, const std::vector<CommandOutput>& outputs);

} // namespace elastolearn
