#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/sim/amplified_scene.hpp>

#include <cmath>

namespace elastolearn::sim {

Scene amplified_scene(Scene scene, double factor) {
  if (!std::isfinite(factor))
    throw InputError("factor", "must be finite, got " + to_text(factor));
  scene.gravity *= factor;
  for (PointLoad& load : scene.loads)
    load.total_force *= factor;
  InitialCondition& initial = scene.initial;
  for (PointLoad& load : initial.static_loads)
    load.total_force *= factor;
  initial.velocity *= factor;
  initial.angular_velocity *= factor;
  if (initial.kind == InitialCondition::Kind::Recorded) {
    const Positions& rest = scene.mesh.rest_positions();
    if (initial.positions.rows() == rest.rows())
      initial.positions = rest + factor * (initial.positions - rest);
    initial.velocities *= factor;
  }
  for (KeyframeMotion& k : scene.keyframes) {
    k.amplitude *= factor;
    for (Vec3& offset : k.offsets)
      offset *= factor;
  }
  return scene;
}

} // namespace elastolearn::sim
