#include <elastolearn/core/progress.hpp>
#include <elastolearn/core/timing.hpp>

#include <chrono>
#include <cstdio>
#include <memory>
#include <unistd.h>

namespace elastolearn {

ProgressCallback terminal_progress(std::string label) {
  struct State {
    Clock::time_point start = Clock::now();
    Clock::time_point last {};
  };
  auto state = std::make_shared<State>();
  const bool tty = ::isatty(2) != 0;
  return [label = std::move(label), state, tty](long done, long total, const std::string& message) {
    const auto now = Clock::now();
    const bool final = total > 0 && done >= total;
    if (!final && now - state->last < std::chrono::milliseconds(tty ? 200 : 2000))
      return;
    state->last = now;
    const double elapsed = std::chrono::duration<double>(now - state->start).count();
    if (total > 0)
      std::fprintf(stderr, "%s%s %ld/%ld (%.0f%%) %.1fs %s%s", tty ? "\r\033[K" : "", label.c_str(),
          done, total, 100.0 * double(done) / double(total), elapsed, message.c_str(),
          tty && !final ? "" : "\n");
    else
      std::fprintf(stderr, "%s%s %ld %.1fs %s%s", tty ? "\r\033[K" : "", label.c_str(), done,
          elapsed, message.c_str(), tty ? "" : "\n");
    std::fflush(stderr);
  };
}

} // namespace elastolearn
