#pragma once
/// \file A simulation that steps on its own thread ahead of its consumer. Work that needs frame t
/// of a trajectory but not the simulator's state (the forward fit's sensitivities) then overlaps
/// the steps after t: on two cores the two halves are each mostly serial (a Newton step's CG
/// solve, a CHOLMOD factorisation), so running them side by side uses the idle core.
#include <elastolearn/core/types.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace elastolearn::sim {

class RunAhead {
  public:
  /// Starts stepping `simulator` (its initial state set) for `frames` steps on a new thread,
  /// publishing frame t's positions and time as its step converges. `simulator` must not be
  /// used elsewhere until this object is destroyed.
  RunAhead(Simulator& simulator, int frames);
  /// Stops the stepping (after the step in progress) and joins the thread.
  ~RunAhead();
  RunAhead(const RunAhead&) = delete;
  RunAhead& operator=(const RunAhead&) = delete;

  /// Blocks until frame t (1 ≤ t ≤ frames) is published; false if the simulation stopped before
  /// it (message() says why). Rethrows what the stepping threw.
  bool wait_for(int t);
  /// Frame t's positions (frame 0: the initial state) and its time; valid after wait_for(t).
  const VecX& positions(int t) const { return m_positions[static_cast<size_t>(t)]; }
  double time(int t) const { return m_times[static_cast<size_t>(t)]; }
  /// Why the simulation stopped early: "frame t: <Newton's message>"; empty otherwise.
  const std::string& message() const { return m_message; }

  private:
  void run(Simulator& simulator);

  std::vector<VecX> m_positions; ///< frames + 1, written once each before it is published
  std::vector<double> m_times;
  std::string m_message; ///< written before `m_failed` is published
  std::exception_ptr m_error; ///< what a step threw (guarded by m_mutex)
  std::mutex m_mutex;
  std::condition_variable m_published;
  int m_ready = 0; ///< frames published (guarded by m_mutex)
  bool m_failed = false; ///< guarded by m_mutex
  std::atomic<bool> m_stop { false };
  std::thread m_thread; ///< last: started once the members above exist
};

} // namespace elastolearn::sim
