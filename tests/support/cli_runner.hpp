#pragma once
/// \file Run the built `elastolearn` executable (ELASTOLEARN_EXECUTABLE) with arguments and
/// capture its exit code and output, for the end-to-end CLI tests.
#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace elastolearn::test {

struct Run {
  int exit_code;
  std::string output; ///< stdout + stderr
};

inline Run run(const std::string& arguments) {
  const std::string command = std::string(ELASTOLEARN_EXECUTABLE) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  Run r{-1, ""};
  std::array<char, 4096> buffer{};
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

} // namespace elastolearn::test
