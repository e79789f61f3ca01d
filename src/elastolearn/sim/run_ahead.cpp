#include <elastolearn/sim/run_ahead.hpp>

namespace elastolearn::sim {

RunAhead::RunAhead(Simulator& simulator, int frames)
    : m_positions(static_cast<size_t>(frames) + 1)
    , m_times(static_cast<size_t>(frames) + 1) {
  m_positions[0] = simulator.positions();
  m_times[0] = simulator.time();
  m_thread = std::thread([this, &simulator] { run(simulator); });
}

RunAhead::~RunAhead() {
  m_stop = true;
  m_thread.join();
}

void RunAhead::run(Simulator& simulator) {
  const int frames = static_cast<int>(m_positions.size()) - 1;
  try {
    for (int t = 1; t <= frames && !m_stop; ++t) {
      const NewtonReport report = simulator.step();
      if (!report.converged) {
        m_message = "frame " + std::to_string(t) + ": " + report.message;
        break;
      }
      m_positions[static_cast<size_t>(t)] = simulator.positions();
      m_times[static_cast<size_t>(t)] = simulator.time();
      const std::lock_guard lock(m_mutex);
      m_ready = t;
      m_published.notify_all();
    }
  } catch (...) {
    const std::lock_guard lock(m_mutex);
    m_error = std::current_exception();
  }
  const std::lock_guard lock(m_mutex);
  m_failed = m_ready < frames;
  m_published.notify_all();
}

bool RunAhead::wait_for(int t) {
  std::unique_lock lock(m_mutex);
  m_published.wait(lock, [&] { return m_ready >= t || m_failed || m_error; });
  if (m_ready < t && m_error)
    std::rethrow_exception(m_error);
  return m_ready >= t;
}

} // namespace elastolearn::sim
