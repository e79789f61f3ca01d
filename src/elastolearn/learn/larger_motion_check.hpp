#pragma once
/// \file Whether a learned material survives motions beyond the one it was learned from (the
/// validation choice's check, Candidate::larger_motion): a user's next motion is rarely the one
/// recorded. Two motions: the recorded one driven harder, and a droop, the one motion of another
/// kind every object has.
#include <elastolearn/core/types.hpp>
#include <elastolearn/sim/scene.hpp>

#include <string>
#include <vector>

namespace elastolearn::learn {

/// How much harder than the recorded motions the larger motion is driven: "half as large again".
inline constexpr double kLargerMotion = 1.5;

/// A material's runs of the larger motion and the droop.
struct LargerMotionCheck {
  bool checked = false; ///< false for the nominals (no correction: nothing to check)
  /// The amplified motion simulated to its end, substeps allowed (Simulator::step), and the
  /// droop held (its static solve converged).
  bool completed = true;
  std::string message; ///< why not (names the motion, and the frame or the droop); or ""
  /// The first frame that converged only in substeps (0: none did). Recorded, not a failure:
  /// a stiffer or more nonlinear material can need them in the violent first step of a motion
  /// it then follows to the end, and the simulator takes them for any material.
  int first_substepped_frame = 0;
};

/// A droop: its body load and the reference's static equilibrium under it.
struct Droop {
  Vec3 acceleration = Vec3::Zero(); ///< [m/s²]; zero: no droop
  VecX reference_equilibrium; ///< flat 3n [m] (empty where the acceleration is zero)
};

/// The droop for a recorded motion, from `run`, the reference material's
/// (the fitted nominal's) run of `scene` (whose material is that reference): a uniform
/// acceleration, like a weight, along the direction the most displaced vertex of `run` moved,
/// as large as makes the reference droop statically kLargerMotion times that displacement
/// (scaled from its linear response, then halved until the reference holds it). Zero where the
/// run does not move or the reference holds no droop; with the equilibrium the reference holds.
Droop reference_droop(const sim::Scene& scene, const std::vector<VecX>& run);

/// The check on `scene` (its material: the nominal with the correction to check). The motion
/// driven kLargerMotion times as hard (sim::amplified_scene) must run to its end, and the
/// object must hold its droop: the static equilibrium under the body acceleration `droop` alone
/// (reference_droop; none where zero), its prescribed vertices where they start, must be
/// found: in one increment from `start` (the reference's equilibrium under the same load, close
/// to a correction's), and else in the scene's load steps from rest, where Newton can stall
/// short of an equilibrium that exists (docs/benchmarks_learning.md, "The full turtle kept its
/// fit"). A correction learned from one kind of motion is constrained only along the deformations
/// that motion visits: one learned from a bar's twist can be far too soft in bending, and finds no
/// equilibrium under a load that bends the bar as far as the twist did. Where the material must be
/// stable is checked on stretches, not here (Candidate::stability): a larger droop of a soft shape
/// strains thin parts far beyond any data (s₁ 2.6 on the quick turtle, trained to 1.32), where no
/// learned correction is trusted. `name` names the motion in the message.
LargerMotionCheck check_larger_motion(const sim::Scene& scene, const std::string& name,
    const Vec3& droop = Vec3::Zero(), const VecX& start = {});

} // namespace elastolearn::learn
