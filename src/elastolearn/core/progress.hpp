#pragma once
/// \file Progress reporting for long work. Library code reports through a callback so that it
/// never prints by itself; the app installs a terminal progress line.
#include <functional>
#include <string>

namespace elastolearn {

/// Called with (done, total, message). `total` may be 0 when unknown.
using ProgressCallback = std::function<void(long done, long total, const std::string& message)>;

/// A progress callback that prints a throttled one-line status to stderr (at most ~5 per second,
/// plus the final one). Use as the default for CLI commands.
ProgressCallback terminal_progress(std::string label);

} // namespace elastolearn
