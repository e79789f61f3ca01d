#pragma once
/// \file What the learning loop records of each step it takes (LearningState::history, the
/// checkpoint, the report, the printed table), one type per kind of step: a loop iteration
/// (LoopRecord: C_k's forward simulation, then the trajectory stages, a damped update or the
/// loop's end) or a step of the forward fit after the loop (ForwardFitRecord). A forward
/// simulation's outcome is its own type (ForwardOutcome). Times in seconds.
#include <elastolearn/learn/trajectory_error.hpp>

#include <optional>
#include <string>
#include <variant>

namespace elastolearn::learn {

/// How a forward simulation (of every motion, with one correction) ended.
enum class ForwardStatus {
  completed, ///< every motion was simulated to its last frame
  diverged, ///< a motion's simulation failed
  unstable, ///< not simulated: the correction's material is unstable (forward-fit trials only)
};

/// "completed", "diverged", "unstable" (the checkpoint's names).
std::string to_string(ForwardStatus status);
/// Inverse of to_string; nullopt for another name.
std::optional<ForwardStatus> forward_status_from_string(const std::string& name);

/// The outcome of a forward simulation: its error at the observed vertices when it completed,
/// why it did not otherwise. Built only by the three named constructors, so an error exists
/// exactly when the simulation completed.
class ForwardOutcome {
  public:
  /// Every motion simulated; `error` at the observed vertices [m] (over all motions).
  static ForwardOutcome completed(const ErrorSummary& error, double seconds);
  /// A simulation failed; `message` names the frame (and the motion, when there are several).
  static ForwardOutcome diverged(std::string message, double seconds);
  /// Not simulated: the correction is unstable; `message` says where.
  static ForwardOutcome unstable(std::string message, double seconds);

  ForwardStatus status() const { return m_status; }
  bool completed() const { return m_status == ForwardStatus::completed; }
  /// The error at the observed vertices [m]. Throws std::logic_error unless completed().
  const ErrorSummary& error() const;
  /// Why the simulation did not complete; empty when it completed.
  const std::string& message() const { return m_message; }
  /// Wall time of the simulations (of the stability check for an unstable trial).
  double seconds() const { return m_seconds; }

  private:
  ForwardOutcome(
      ForwardStatus status, const ErrorSummary& error, std::string message, double seconds);
  ForwardStatus m_status;
  ErrorSummary m_error;
  std::string m_message;
  double m_seconds;
};

/// What the trajectory stages of one loop iteration measured: constrained simulation, POD basis,
/// space-time optimisation, control forces, stress reconstruction and the stability shrink,
/// which give C_{k+1}. Counts, objectives and times are sums over the motions.
struct SpaceTimeStages {
  int modes = 0; ///< POD modes
  /// √(mean r²) of the optimised trajectories (over every motion's steps and free dofs) [N]
  double control_force_rms = 0;
  double space_time_initial = 0; ///< E at the constrained simulation
  double space_time_objective = 0; ///< E after optimisation
  int space_time_iterations = 0; ///< Gauss–Newton iterations
  int centres = 0; ///< RBF kernels of C_{k+1}
  /// RMS force misfit of C_{k+1} against its targets (every motion's frames) [N]
  double correction_misfit = 0;
  double correction_target = 0; ///< RMS of those targets [N]
  /// The reconstructed correction's material_stability over its trajectories' stretches
  /// (min_relative_eigenvalue: < 0 where it is unstable).
  double stability = 0;
  /// The fraction of the reconstructed correction kept to stay stable (1: all; 0: none, the
  /// next iteration simulates the nominal).
  double step_kept = 1;
  /// Conditions the reconstruction was held to so that it stays stable (stability_cuts.hpp;
  /// 0: it was stable as fitted).
  int stability_cuts = 0;
  double seconds_pod = 0, seconds_constrained = 0, seconds_space_time = 0,
         seconds_reconstruction = 0;
  double seconds() const {
    return seconds_pod + seconds_constrained + seconds_space_time + seconds_reconstruction;
  }
};

/// C_k's forward simulation diverged, or (LearningOptions::backtrack) its error was not below
/// the best one's, and C_{k+1} = ½ (C_k + best) is tried next (no trajectory stages).
struct DampedUpdate { };

/// The loop ended with this iteration's forward simulation: the last check of the last
/// correction, or a failed step past LearningOptions::free_halvings and patience. No C_{k+1}.
struct LoopEnd { };

/// What followed C_k's forward simulation in a loop iteration.
using LoopNext = std::variant<SpaceTimeStages, DampedUpdate, LoopEnd>;

/// One iteration k of the loop (paper 000 §3): C_k's forward simulation and what followed it.
struct LoopRecord {
  int iteration = 0; ///< k (0: the nominal model)
  ForwardOutcome forward; ///< of C_k: completed or diverged (the loop simulates every C_k)
  LoopNext next;
  /// The trajectory stages, or null when there were none.
  const SpaceTimeStages* stages() const { return std::get_if<SpaceTimeStages>(&next); }
  bool damped_update() const { return std::holds_alternative<DampedUpdate>(next); }
};

/// One trial step of the forward fit after the loop (LearningOptions::forward_fit): accepted
/// (it lowered the error and became the best correction), rejected (μ × 10), or rejected
/// because its simulation diverged or, unsimulated, because it is unstable.
struct ForwardFitRecord {
  int iteration = 0; ///< continues the loop's numbering
  ForwardOutcome forward; ///< of the trial
  bool accepted = false; ///< only a completed trial is accepted
  int centres = 0; ///< RBF kernels of the fitted correction
};

/// One step of a learning run, in the order they ran: the loop's iterations, then the forward
/// fit's steps (LearningState::history).
using IterationRecord = std::variant<LoopRecord, ForwardFitRecord>;

/// k of either kind of step.
int iteration_of(const IterationRecord& record);
/// The forward simulation of either kind of step.
const ForwardOutcome& forward_of(const IterationRecord& record);
/// The step's wall time: its forward simulation and (loop iterations) its trajectory stages.
double seconds_of(const IterationRecord& record);
/// The trajectory stages of a loop iteration that ran them, else null.
const SpaceTimeStages* stages_of(const IterationRecord& record);
/// A forward-fit step, else null.
const ForwardFitRecord* forward_fit_of(const IterationRecord& record);

} // namespace elastolearn::learn
