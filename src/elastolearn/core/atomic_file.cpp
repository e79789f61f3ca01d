#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>

#include <fstream>
#include <sstream>
#include <system_error>
#include <unistd.h>

namespace elastolearn {

AtomicFile::AtomicFile(std::filesystem::path target)
    : m_target(std::move(target)) {
  if (m_target.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(m_target.parent_path(), ec);
    if (ec)
      throw InputError(m_target.parent_path().string(), "cannot create directory: " + ec.message());
  }
  m_temp = m_target;
  m_temp += ".tmp-" + std::to_string(::getpid());
}

AtomicFile::~AtomicFile() {
  if (!m_committed) {
    std::error_code ec;
    std::filesystem::remove(m_temp, ec);
  }
}

void AtomicFile::commit() {
  std::error_code ec;
  std::filesystem::rename(m_temp, m_target, ec);
  if (ec)
    throw InputError(m_target.string(), "cannot write output: " + ec.message());
  m_committed = true;
}

void write_text_file_atomic(const std::filesystem::path& path, const std::string& contents) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << contents;
    out.close();
    if (!out)
      throw InputError(path.string(), "cannot write file");
  }
  file.commit();
}

std::string read_text_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path.string(), "is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path.string(), "cannot open file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad())
    throw InputError(path.string(), "cannot read file");
  return ss.str();
}

} // namespace elastolearn
