#pragma once
/// \file The clamped bar that tests and benchmarks simulate: a box of 6-tet cubes
/// (mesh::make_box_bar) held fixed at x = 0, with lumped mass. Header-only, so that each test
/// executable links only the layers it tests; bench/ includes it too (bench/CMakeLists.txt).
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>
#include <elastolearn/sim/scene.hpp>

#include <array>
#include <memory>

namespace elastolearn::test {

/// What differs between the bars. Everything else is sim::Scene's default (lumped mass, CHOLMOD,
/// default Newton options, at rest); callers set initial conditions, solver options and names on
/// the returned scene.
struct BarOptions {
  Vec3 size = Vec3(0.4, 0.1, 0.1); ///< [m], the box [0, size.x] × [0, size.y] × [0, size.z]
  std::array<int, 3> cells { 8, 2, 2 }; ///< cubes along x, y, z (6 tets each)
  material::ElasticModelType model = material::ElasticModelType::Corotated;
  double young = 1e5; ///< E [Pa]
  double poisson = 0.4; ///< ν
  double density = 1000; ///< ρ [kg/m³]
  /// Rayleigh damping α₀ [1/s], α₁ [s]. When both are 0 the material has no damping model at all
  /// (not a zero one).
  double alpha0 = 0, alpha1 = 0;
  Vec3 gravity = Vec3(0, -9.81, 0); ///< [m/s²]
  double dt = 1e-3; ///< [s]
  int frames = 100;
};

/// The scene of a bar clamped at x = 0 (every vertex of that face is fixed).
inline sim::Scene bar_scene(const BarOptions& o = {}) {
  sim::Scene s;
  s.mesh = mesh::make_box_bar(o.size, o.cells);
  s.material.elastic = material::make_elastic_model(
      o.model, material::Lame::from_young_poisson(o.young, o.poisson));
  if (o.alpha0 != 0 || o.alpha1 != 0)
    s.material.damping = std::make_shared<material::RayleighDamping>(o.alpha0, o.alpha1);
  s.material.density = o.density;
  s.fixed_vertices = mesh::vertices_with_min_coordinate(s.mesh, 0, 1e-9);
  s.gravity = o.gravity;
  s.dt = o.dt;
  s.frames = o.frames;
  return s;
}

/// The 96-tet bar (E 3e5, α₁ 0.005 s, 2 ms steps) swinging from ω = 2 rad/s about z under
/// gravity for `frames` frames: a motion whose initial velocity is not zero.
inline sim::Scene swinging_bar(int frames) {
  sim::Scene s = bar_scene({ .young = 3e5, .alpha1 = 0.005, .dt = 2e-3, .frames = frames });
  s.initial.kind = sim::InitialCondition::Kind::Velocity;
  s.initial.angular_velocity = Vec3(0, 0, 2.0);
  return s;
}

/// `s` with Newton set up to fail its first step: one iteration to a tolerance it cannot meet,
/// no substeps, no retry with the exact tangent.
inline sim::Scene failing_first_step(sim::Scene s) {
  s.newton.max_iterations = 1;
  s.newton.relative_tolerance = 1e-12;
  s.newton.max_step_halvings = 0;
  s.newton.retry_exact_tangent = false;
  return s;
}

/// The 240-tet bar the learning tests learn from (0.4 × 0.1 × 0.1 m, ν = 0.43, α₁ 0.01 s, 60
/// frames of 4 ms): at rest (a droop), or with `swing` turning at 2 rad/s about z.
inline sim::Scene learning_bar(material::ElasticModelType type, double young, bool swing) {
  sim::Scene s = bar_scene({ .cells = { 10, 2, 2 },
      .model = type,
      .young = young,
      .poisson = 0.43,
      .alpha1 = 0.01,
      .dt = 4e-3,
      .frames = 60 });
  if (swing) {
    s.initial.kind = sim::InitialCondition::Kind::Velocity;
    s.initial.angular_velocity = Vec3(0, 0, 2.0);
  }
  return s;
}

} // namespace elastolearn::test
