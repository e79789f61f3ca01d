#include <elastolearn/mesh/external_program.hpp>

#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace elastolearn::mesh {

ProgramResult run_program(const std::filesystem::path& program,
    const std::vector<std::string>& args, const std::filesystem::path& log_file) {
  std::vector<std::string> storage;
  storage.push_back(program.string());
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage)
    argv.push_back(s.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(
      &actions, STDOUT_FILENO, log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw InputError(program.string(), std::string("cannot start program: ") + std::strerror(rc));

  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw InputError(program.string(), std::string("waitpid failed: ") + std::strerror(errno));
  }
  ProgramResult result;
  if (WIFEXITED(status))
    result.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status))
    result.signal = WTERMSIG(status);
  try {
    result.output = read_text_file(log_file);
  } catch (const InputError&) {
    result.output.clear();
  }
  constexpr std::size_t kKeep = 64 * 1024;
  if (result.output.size() > kKeep)
    result.output.erase(0, result.output.size() - kKeep);
  return result;
}

TemporaryDirectory::TemporaryDirectory(const std::string& prefix) {
  std::string templ = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (::mkdtemp(templ.data()) == nullptr)
    throw InputError(
        templ, std::string("cannot create temporary directory: ") + std::strerror(errno));
  m_path = templ;
}

TemporaryDirectory::~TemporaryDirectory() {
  std::error_code ec;
  std::filesystem::remove_all(m_path, ec);
}

} // namespace elastolearn::mesh
