#include <elastolearn/core/error.hpp>
#include <elastolearn/sim/scene.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::sim {

std::vector<int> Scene::prescribed_vertices() const {
  std::vector<int> out = fixed_vertices;
  for (const auto& k : keyframes)
    out.insert(out.end(), k.vertices.begin(), k.vertices.end());
  if (tracked)
    out.insert(out.end(), tracked->vertices.begin(), tracked->vertices.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void Scene::validate() const {
  const int n = mesh.num_vertices();
  if (n == 0)
    throw InputError("mesh", "scene has no mesh");
  if (!material.elastic)
    throw InputError("material", "no elastic model");
  if (!(material.density > 0))
    throw InputError("material.density", "must be positive");
  if (!(dt > 0 && std::isfinite(dt)))
    throw InputError("dt", "must be a positive number");
  if (frames < 1)
    throw InputError("frames", "must be at least 1");
  if (!gravity.allFinite())
    throw InputError("gravity", "must be finite");
  for (int v : fixed_vertices)
    if (v < 0 || v >= n)
      throw InputError("fixed",
          "vertex index " + std::to_string(v) + " out of range [0, " + std::to_string(n) + ")");
  for (const auto& k : keyframes)
    k.validate(n);
  if (tracked)
    tracked->validate(n);
  auto check_loads = [&](const std::vector<PointLoad>& loads, const std::string& field) {
    for (const auto& l : loads) {
      if (l.vertices.empty())
        throw InputError(field, "load has no vertices");
      for (int v : l.vertices)
        if (v < 0 || v >= n)
          throw InputError(field, "vertex index " + std::to_string(v) + " out of range");
      if (!l.total_force.allFinite())
        throw InputError(field, "force must be finite");
    }
  };
  check_loads(loads, "loads");
  check_loads(initial.static_loads, "initial.loads");
  if (initial.kind == InitialCondition::Kind::Recorded) {
    const auto rows = [](const Positions& p) { return std::to_string(p.rows()); };
    if (initial.positions.rows() != n || !initial.positions.allFinite())
      throw InputError("initial",
          "the recorded state must hold " + std::to_string(n) + " finite positions, got "
              + rows(initial.positions));
    if (initial.velocities.rows() != 0
        && (initial.velocities.rows() != n || !initial.velocities.allFinite()))
      throw InputError("initial",
          "the recorded velocities must be absent or " + std::to_string(n) + " finite vectors, got "
              + rows(initial.velocities));
    if (!std::isfinite(initial.time))
      throw InputError("initial", "the recorded time must be finite");
  }
  if (initial.kind == InitialCondition::Kind::StaticLoad && prescribed_vertices().empty())
    throw InputError("initial", "a static initial state needs fixed or keyframed vertices");
  newton.validate();
}

} // namespace elastolearn::sim
