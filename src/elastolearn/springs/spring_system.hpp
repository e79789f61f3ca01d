#pragma once
/// \file Mass-spring systems (ropes, cloth): topology, rest state, masses, pins, loads, and the
/// `SpringStepper` interface every simulator of this layer implements (reference and learned).
#include <elastolearn/core/types.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace elastolearn::springs {

/// Topology and rest state of a mass-spring system. Call `finalize()` after filling it.
struct SpringSystem {
  Positions rest; ///< n×3 rest positions [m]
  Edges springs; ///< s×2 node pairs (i, j), i ≠ j, no duplicates
  VecX rest_lengths; ///< s rest lengths [m] (finalize fills it from `rest` if empty)
  VecX masses; ///< n masses [kg] (finalize fills ones if empty)
  std::vector<char> pinned; ///< n flags: pinned nodes never move (finalize fills zeros if empty)
  Faces faces; ///< triangles for viewing (cloth), may be empty

  /// Node → incident springs (CSR): springs of node a are incident[offsets[a] .. offsets[a+1]).
  std::vector<int> incident_offsets;
  std::vector<int> incident;
  /// Per-node count of incident springs (the paper's n in §6).
  std::vector<int> degree;

  int node_count() const { return static_cast<int>(rest.rows()); }
  int spring_count() const { return static_cast<int>(springs.rows()); }
  /// Validate (indices in range, no self/duplicate springs, positive lengths and masses, finite
  /// values) and build the incidence. Throws InputError("spring system.<field>", ...).
  void finalize();
};

/// Where a cloth lies at rest.
enum class ClothPlane {
  vertical, ///< x–y plane, row 0 at the top (y = 0), rows going down −y
  horizontal, ///< x–z plane (y = 0), row 0 is the pinned edge; it swings down under −y gravity
};
/// Which cloth nodes are pinned.
enum class ClothPins { top_corners, top_row, none };

std::string_view to_string(ClothPlane plane);
std::string_view to_string(ClothPins pins);
/// Inverse of to_string ("vertical", "horizontal"); throws InputError(where, ...).
ClothPlane cloth_plane_from_string(const std::string& name, const std::string& where);
/// Inverse of to_string ("top-corners", "top-row", "none"); throws InputError(where, ...).
ClothPins cloth_pins_from_string(const std::string& name, const std::string& where);

/// Options of `make_cloth`.
struct ClothOptions {
  int columns = 5; ///< nodes per row (x)
  int rows = 5; ///< rows
  double spacing = 1.0; ///< structural rest length [m] (paper: unit rest length)
  bool shear = true; ///< 8-neighbour springs (paper §5): add both diagonals of each quad
  ClothPlane plane = ClothPlane::vertical;
  ClothPins pins = ClothPins::top_corners;
  double node_mass = 1.0; ///< [kg] (paper: unit mass)
};

/// The most nodes a generated rope or cloth may have: far beyond what the experiments use, it
/// keeps a mistyped count (10⁹) a clear error instead of an allocation failure.
constexpr long long kMaxSpringNodes = 10'000'000;

/// Rope of `nodes` nodes along +x with spacing `rest_length`, node 0 pinned (paper §4).
/// Throws InputError for nodes < 2 or > kMaxSpringNodes, or non-positive length/mass.
SpringSystem make_rope(int nodes, double rest_length = 1.0, double node_mass = 1.0);
/// Rectangular cloth; node (column i, row r) has index r·columns + i. Throws InputError, also
/// for more than kMaxSpringNodes nodes.
SpringSystem make_cloth(const ClothOptions& options);
/// Nodes of the bottom row of a cloth made by make_cloth (row rows−1).
std::vector<int> cloth_bottom_row(const ClothOptions& options);

/// External loads: per-node forces [N] (n×3, or empty for none) and gravity [m/s²].
struct Loads {
  Positions forces;
  Vec3 gravity = Vec3::Zero();
};

/// Positions and velocities of all nodes.
struct SpringState {
  Positions x; ///< n×3 [m]
  Positions v; ///< n×3 [m/s]
};

/// The rest state with zero velocity.
SpringState rest_state(const SpringSystem& system);

/// One time step of a mass-spring simulator. Implemented by the reference semi-implicit Euler
/// simulator and by the learned simulators (paper, explicit, implicit modes).
class SpringStepper {
  public:
  virtual ~SpringStepper() = default;
  /// Advance `state` by dt() in place. Pinned nodes keep their position and zero velocity.
  virtual void step(SpringState& state) = 0;
  /// Replace the external loads (forces must be n×3 or empty). Throws InputError.
  virtual void set_loads(const Loads& loads) = 0;
  virtual const SpringSystem& system() const = 0;
  /// Time step [s].
  virtual double dt() const = 0;
  /// True if a node's update depends only on the nodes it shares a spring with (explicit
  /// schemes); false for schemes with a global solve. Used by `solve_fixed_point`.
  virtual bool is_local() const = 0;
  /// Short name for reports ("reference", "paper", "explicit", "implicit").
  virtual std::string_view name() const = 0;
};

namespace detail {
/// Validate loads against a system; returns the n×3 force array (zeros when empty).
Positions checked_forces(const SpringSystem& system, const Loads& loads);
} // namespace detail

} // namespace elastolearn::springs
