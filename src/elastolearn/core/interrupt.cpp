#include <elastolearn/core/interrupt.hpp>

#include <atomic>
#include <csignal>

namespace elastolearn {

namespace {
std::atomic<bool> g_interrupted { false };

extern "C" void on_signal(int signal) {
  if (g_interrupted.exchange(true)) {
    std::signal(signal, SIG_DFL); // second Ctrl-C: give up immediately
    std::raise(signal);
  }
}
} // namespace

void install_interrupt_handler() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

bool interrupt_requested() {
  return g_interrupted.load(std::memory_order_relaxed);
}

void set_interrupt_requested(bool value) {
  g_interrupted.store(value);
}

} // namespace elastolearn
