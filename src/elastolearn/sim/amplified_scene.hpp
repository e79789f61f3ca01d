#pragma once
/// \file A larger motion of the same kind as a scene's: the scene driven harder. The recipe asks
/// every learned material to survive one (learn/learning_recipe.hpp): a user's next motion is
/// rarely the one recorded.
#include <elastolearn/sim/scene.hpp>

namespace elastolearn::sim {

/// `scene` driven `factor` times as hard: gravity, the point loads (during the motion and the
/// static ones of the initial state), the initial velocity field, a recorded initial state's
/// displacement from rest and its velocities, and the keyframes' amplitudes and offsets, each
/// scaled by `factor`. Every drive of a scene is linear in these, so for a linear material (or
/// any material at small strain) the displacements from rest scale by `factor`; for a nonlinear
/// one it is the larger motion of the same kind (a negative factor mirrors the drive, 0 leaves
/// the object at rest). Throws InputError("factor", ...) unless factor is finite.
Scene amplified_scene(Scene scene, double factor);

} // namespace elastolearn::sim
