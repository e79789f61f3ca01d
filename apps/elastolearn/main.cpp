// elastolearn: data-driven simulation of elastic solids. See README.md and docs/.
#include "command.hpp"

#include <elastolearn/config.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/interrupt.hpp>

#include <algorithm>
#include <cstdio>

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
  install_interrupt_handler();
  auto& registry = app::command_registry();
  std::sort(registry.begin(), registry.end(),
      [](const auto& a, const auto& b) { return a.order < b.order; });
  for (const auto& entry : registry)
    entry.add(root);
  try {
    root.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return root.exit(e);
  } catch (const InputError& e) {
    std::fprintf(stderr, "elastolearn: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "elastolearn: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
