#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>

#include <system_error>
#include <unistd.h>

namespace elastolearn {

namespace fs = std::filesystem;

namespace {

/// Absolute, lexically normal, with the existing part's symbolic links resolved and without a
/// trailing separator ("out/" and "out" are one folder).
fs::path resolved(const fs::path& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec)
    p = path;
  const fs::path canonical = fs::weakly_canonical(p, ec);
  p = ec ? p.lexically_normal() : canonical.lexically_normal();
  if (!p.has_filename() && p.has_parent_path() && p != p.root_path())
    p = p.parent_path();
  return p;
}

bool present_at(const fs::path& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

/// Throws unless `output` exists as its kind or can be created as one.
void check_creatable(const CommandOutput& output) {
  const std::string where = output.path.string();
  std::error_code ec;
  const fs::file_status status = fs::status(output.path, ec);
  const bool present = fs::exists(status);
  if (present && output.kind == OutputKind::file && fs::is_directory(status))
    throw InputError(where, "is a folder, but the " + output.role + " must be a file");
  if (present && output.kind == OutputKind::folder && !fs::is_directory(status))
    throw InputError(where, "exists and is not a folder, but the " + output.role + " is a folder");
  // The folder that must be writable: a file is written beside itself and renamed; a missing
  // folder (or a file's missing folder) is created inside its nearest existing ancestor.
  const fs::path target = resolved(output.path);
  fs::path folder = output.kind == OutputKind::folder && present ? target : target.parent_path();
  while (!present_at(folder) && folder.has_parent_path() && folder.parent_path() != folder)
    folder = folder.parent_path();
  if (!fs::is_directory(folder, ec))
    throw InputError(where, "cannot be created: " + folder.string() + " is not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw InputError(where, "cannot be written: no permission to write in " + folder.string());
}

} // namespace

bool same_file(const fs::path& a, const fs::path& b) {
  const bool a_exists = present_at(a), b_exists = present_at(b);
  if (a_exists && b_exists) {
    std::error_code ec;
    const bool equivalent = fs::equivalent(a, b, ec);
    if (!ec)
      return equivalent;
  }
  if (a_exists != b_exists)
    return false;
  return resolved(a) == resolved(b);
}

void check_command_paths(
    const std::vector<CommandInput>& inputs, const std::vector<CommandOutput>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const CommandOutput& out = outputs[i];
    if (out.path.empty())
      throw InputError(out.role, "empty path");
    for (const CommandInput& in : inputs) {
      if (!in.path.empty() && same_file(out.path, in.path)) {
        const std::string spelled
            = in.path == out.path ? std::string() : " (given as " + in.path.string() + ")";
        throw InputError(out.path.string(),
            "the " + out.role + " is the " + in.role + spelled
                + " that this command reads; writing it would replace the input, so nothing was "
                  "done: choose another output path");
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (same_file(out.path, outputs[j].path)) {
        throw InputError(out.path.string(),
            "the " + out.role + " and the " + outputs[j].role
                + " are the same file; give them different paths");
      }
    }
  }
  for (const CommandOutput& out : outputs)
    check_creatable(out);
}

} // namespace elastolearn
