#pragma once
/// \file Whether a learned material survives a motion larger than the one it was learned from
/// (the validation choice's check, Candidate::larger_motion): a user's next motion is rarely the
/// one recorded.
#include <elastolearn/sim/scene.hpp>

#include <string>

namespace elastolearn::learn {

/// How much harder than the recorded motions the larger motion is driven: "half as large again".
inline constexpr double kLargerMotion = 1.5;

/// A material's run of a larger motion.
struct LargerMotionCheck {
  bool checked = false; ///< false for the nominals (no correction: nothing to check)
  /// The amplified motion simulated to its end, substeps allowed (Simulator::step).
  bool completed = true;
  std::string message; ///< why it did not (names the motion and the frame); or ""
  /// The first frame that converged only in substeps (0: none did). Recorded, not a failure:
  /// a stiffer or more nonlinear material can need them in the violent first step of a motion
  /// it then follows to the end, and the simulator takes them for any material.
  int first_substepped_frame = 0;
};

/// The check on `scene` (its material: the nominal with the correction to check) driven
/// kLargerMotion times as hard (sim::amplified_scene): the run must complete. Where the material
/// must be stable is checked on stretches, not here (Candidate::stability): a larger droop of a
/// soft shape strains thin parts far beyond any data (s₁ 2.6 on the quick turtle, trained to
/// 1.32), where no learned correction is trusted. `name` names the motion in the message.
LargerMotionCheck check_larger_motion(const sim::Scene& scene, const std::string& name);

} // namespace elastolearn::learn
