#pragma once
/// \file Wall-clock timing of the stages that reports and benchmarks give in seconds.
#include <chrono>

namespace elastolearn {

/// The clock of every duration the library measures: monotonic, so a change of the system time
/// during a run does not show up as a negative or huge stage time.
using Clock = std::chrono::steady_clock;

/// Seconds elapsed since `start` (a Clock::now() taken earlier).
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace elastolearn
