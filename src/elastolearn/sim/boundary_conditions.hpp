#pragma once
/// \file Boundary and initial conditions of a scene: keyframed vertices, point loads, initial
/// state.
#include <elastolearn/core/types.hpp>
#include <elastolearn/fem/force_term.hpp>

#include <limits>
#include <string>
#include <vector>

namespace elastolearn::sim {

/// Prescribed motion of a vertex group: rest position + offset(t) [m].
/// - sinusoid: offset(t) = amplitude · sin(2π·frequency·t) for t ≤ until, then held;
/// - piecewise-linear: offsets interpolated between (times[k], offsets[k]), held outside.
struct KeyframeMotion {
  enum class Kind { Sinusoid, PiecewiseLinear };
  std::vector<int> vertices;
  Kind kind = Kind::Sinusoid;
  Vec3 amplitude = Vec3::Zero();
  double frequency = 1; ///< [Hz]
  double until = std::numeric_limits<double>::infinity(); ///< [s]
  std::vector<double> times; ///< piecewise-linear knots [s]
  std::vector<Vec3> offsets; ///< piecewise-linear values [m]

  Vec3 offset_at(double t) const;
  /// Throws InputError (field "keyframes") if inconsistent.
  void validate(int num_vertices) const;
};

/// Vertices that follow recorded positions: the constrained forward simulation of paper 000
/// (Eqs. 6–8), where observed vertices are prescribed from their data and the rest is simulated.
/// Frame k holds the positions at time start_time + k·dt; between frames they are interpolated
/// linearly, outside the recording they are held.
struct TrackedVertices {
  std::vector<int> vertices; ///< k vertex indices
  std::vector<Positions> positions; ///< frames, each k×3 [m]
  double dt = 0; ///< [s]
  double start_time = 0; ///< [s]
  /// Position of tracked vertex j (row of `positions`) at time t.
  Vec3 position_at(int j, double t) const;
  /// Throws InputError (field "tracked") if inconsistent.
  void validate(int num_vertices) const;
};

/// A force spread evenly over a vertex group, active while t < release_time.
struct PointLoad {
  std::vector<int> vertices;
  Vec3 total_force = Vec3::Zero(); ///< [N], split evenly
  double release_time = std::numeric_limits<double>::infinity(); ///< [s]
};

/// How the motion starts.
/// - Rest: rest positions (prescribed vertices where their motion puts them at t = 0), zero
///   velocity, t = 0.
/// - Velocity: rest positions with the rigid velocity field below, t = 0.
/// - StaticLoad: static equilibrium under gravity + static_loads, zero velocity, t = 0.
/// - Recorded: a given state (e.g. a frame of a trajectory file) at `time`; the simulation
///   continues from it, so keyframes and load release times keep the clock of the recording.
///   Prescribed vertices are put at their prescribed positions at `time`; fixed vertices get
///   zero velocity, every other vertex the given one.
struct InitialCondition {
  enum class Kind { Rest, Velocity, StaticLoad, Recorded };
  Kind kind = Kind::Rest;
  Vec3 velocity = Vec3::Zero(); ///< Velocity: v(X) = velocity + angular_velocity × (X − center)
  Vec3 angular_velocity = Vec3::Zero(); ///< [rad/s]
  Vec3 center = Vec3::Zero(); ///< [m]
  std::vector<PointLoad>
      static_loads; ///< StaticLoad: equilibrium under gravity + these, then released
  int load_steps = 5; ///< StaticLoad: load increments of the static solve
  Positions positions; ///< Recorded: n×3 [m]
  Positions velocities; ///< Recorded: n×3 [m/s], or empty for zero velocities
  double time = 0; ///< Recorded: time of the state [s], where the simulation starts
};

/// The loads of a scene as one force term: gravity M g plus point loads until their release.
class ExternalLoads final : public fem::ForceTerm {
  public:
  /// \param dof_masses  lumped masses per dof (3n) for gravity [kg]
  ExternalLoads(const VecX& dof_masses, const Vec3& gravity, std::vector<PointLoad> loads);
  void add_force(const fem::ForceState& state, VecX& f) override;
  /// Scale applied to all loads (load stepping of the static solve); default 1.
  void set_scale(double scale) { m_scale = scale; }

  private:
  VecX m_gravity_force;
  std::vector<PointLoad> m_loads;
  double m_scale = 1;
};

} // namespace elastolearn::sim
