#pragma once
/// \file A simulation scene: everything `simulate` needs, independent of file formats
/// (io/scene_file reads it from JSON).
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/fem/mass.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/sim/boundary_conditions.hpp>
#include <elastolearn/sim/linear_solver.hpp>
#include <elastolearn/sim/newton.hpp>

#include <memory>
#include <string>
#include <vector>

namespace elastolearn::sim {

struct Scene {
  std::string name = "scene";
  mesh::TetMesh mesh;
  fem::MaterialModel material;
  fem::MassType mass = fem::MassType::Lumped;
  Vec3 gravity = Vec3::Zero(); ///< [m/s²]
  std::vector<int> fixed_vertices; ///< held at rest
  std::vector<KeyframeMotion> keyframes; ///< prescribed motion
  std::vector<PointLoad> loads; ///< during the motion
  std::shared_ptr<const TrackedVertices> tracked; ///< optional: vertices following recorded data
  InitialCondition initial;
  double dt = 1e-3; ///< time step [s]
  int frames = 100; ///< number of steps (output has frames + 1 states)
  NewtonOptions newton;
  LinearSolverType linear_solver = LinearSolverType::Cholmod;

  /// Vertices whose positions are prescribed (fixed ∪ keyframed ∪ tracked), sorted, unique.
  std::vector<int> prescribed_vertices() const;
  /// Throws InputError naming the offending field.
  void validate() const;
};

} // namespace elastolearn::sim
