#include <elastolearn/config.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/report_resources.hpp>

#include <cstdlib>
#include <string>
#include <system_error>
#include <vector>

namespace elastolearn::io {

namespace fs = std::filesystem;

std::filesystem::path report_resource_dir() {
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("ELASTOLEARN_SHARE_DIR"); dir && *dir)
    candidates.push_back(fs::path(dir) / "report");
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec)
    candidates.push_back(exe.parent_path().parent_path() / "share" / "elastolearn" / "report");
  candidates.push_back(fs::path(ELASTOLEARN_INSTALL_SHARE_DIR) / "report");
  candidates.push_back(fs::path(ELASTOLEARN_BUILD_SHARE_DIR) / "report");
  std::string looked;
  for (const fs::path& dir : candidates) {
    if (fs::is_regular_file(dir / "report_plots.py", ec))
      return dir;
    looked += (looked.empty() ? "" : ", ") + dir.string();
  }
  throw InputError("report",
      "cannot find the report's files (report_plots.py) in " + looked
          + " (set ELASTOLEARN_SHARE_DIR to the folder holding report/)");
}

std::filesystem::path report_python() {
  if (const char* python = std::getenv("ELASTOLEARN_PYTHON"); python && *python)
    return python;
  return "/usr/bin/python3";
}

} // namespace elastolearn::io
