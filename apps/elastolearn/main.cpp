// elastolearn: data-driven simulation of elastic solids. See README.md and docs/.
#include "command.hpp"

#include <elastolearn/config.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/interrupt.hpp>

#include <algorithm>
#include <cstdio>
#include <new>

namespace elastolearn::app {

std::vector<CommandEntry>& command_registry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

bool register_command(int order, CommandAdder add) {
  command_registry().push_back({ order, std::move(add) });
  return true;
}

} // namespace elastolearn::app

int main(int argc, char** argv) {
  using namespace elastolearn;
  CLI::App root { "elastolearn " ELASTOLEARN_VERSION
                  " - learn how elastic solids move, and simulate them" };
  root.set_version_flag("--version", ELASTOLEARN_VERSION);
  root.require_subcommand(1);
  // Usage errors are bad input like any other: one line, exit code 2 (see main's catch).
  root.failure_message([](const CLI::App* app, const CLI::Error& e) {
    std::string line = "elastolearn: error: " + printable_line(e.what());
    const auto unparsed = app->remaining();
    if (!unparsed.empty() && app->get_subcommands().empty())
      line += ": unknown command '" + printable_line(unparsed.front(), 60) + "'";
    return line + " (see --help)\n";
  });
  install_interrupt_handler();
  auto& registry = app::command_registry();
  std::sort(registry.begin(), registry.end(),
      [](const auto& a, const auto& b) { return a.order < b.order; });
  for (const auto& entry : registry)
    entry.add(root);
  try {
    root.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = root.exit(e);
    // CLI11's own codes for usage errors are 100..127; RuntimeError(n) from a command and
    // --help/--version (0) keep theirs.
    return code >= 100 ? 2 : code;
  } catch (const InputError& e) {
    std::fprintf(stderr, "elastolearn: error: %s\n", printable_line(e.what()).c_str());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr,
        "elastolearn: error: out of memory (are the inputs' sizes and counts what you meant?)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "elastolearn: internal error: %s\n", printable_line(e.what()).c_str());
    return 3;
  }
  return 0;
}
