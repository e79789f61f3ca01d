#pragma once
// Subcommand registry. Each cmd_<name>.cpp defines a function that adds its subcommand (options
// and callback) to the root CLI::App, and registers it with ELASTOLEARN_COMMAND, so adding a
// command touches no shared file. Callbacks parse, call the library, print — no numerics here.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace elastolearn::app {

using CommandAdder = std::function<void(CLI::App& root)>;

struct CommandEntry {
  int order; ///< position in `--help`
  CommandAdder add;
};

std::vector<CommandEntry>& command_registry();
bool register_command(int order, CommandAdder add);

} // namespace elastolearn::app

#define ELASTOLEARN_COMMAND(order, fn)                                                             \
  namespace {                                                                                      \
  [[maybe_unused]] const bool registered_##fn = ::elastolearn::app::register_command(order, fn);   \
  }
