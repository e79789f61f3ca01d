#include <elastolearn/springs/spring_system.hpp>

#include <elastolearn/core/error.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace elastolearn::springs {

void SpringSystem::finalize() {
  const int n = node_count(), s = spring_count();
  if (n == 0)
    throw InputError("spring system.nodes", "no nodes");
  if (!rest.allFinite())
    throw InputError("spring system.rest", "non-finite rest position");
  if (masses.size() == 0)
    masses = VecX::Ones(n);
  if (masses.size() != n)
    throw InputError("spring system.masses",
        "expected " + std::to_string(n) + " values, got " + std::to_string(masses.size()));
  for (int a = 0; a < n; ++a)
    if (!(masses[a] > 0.0) || !std::isfinite(masses[a]))
      throw InputError("spring system.masses[" + std::to_string(a) + "]",
          "must be > 0, got " + std::to_string(masses[a]));
  if (pinned.empty())
    pinned.assign(static_cast<std::size_t>(n), 0);
  if (static_cast<int>(pinned.size()) != n)
    throw InputError("spring system.pinned", "expected " + std::to_string(n) + " flags");
  std::vector<std::pair<int, int>> seen;
  seen.reserve(static_cast<std::size_t>(s));
  for (int k = 0; k < s; ++k) {
    const int i = springs(k, 0), j = springs(k, 1);
    const std::string where = "spring system.springs[" + std::to_string(k) + "]";
    if (i < 0 || i >= n || j < 0 || j >= n)
      throw InputError(where,
          "node index out of range [0, " + std::to_string(n) + "): (" + std::to_string(i) + ", "
              + std::to_string(j) + ")");
    if (i == j)
      throw InputError(where, "connects node " + std::to_string(i) + " to itself");
    seen.emplace_back(std::min(i, j), std::max(i, j));
  }
  std::sort(seen.begin(), seen.end());
  const auto dup = std::adjacent_find(seen.begin(), seen.end());
  if (dup != seen.end())
    throw InputError("spring system.springs",
        "duplicate spring between nodes " + std::to_string(dup->first) + " and "
            + std::to_string(dup->second));
  if (rest_lengths.size() == 0) {
    rest_lengths.resize(s);
    for (int k = 0; k < s; ++k)
      rest_lengths[k] = (rest.row(springs(k, 0)) - rest.row(springs(k, 1))).norm();
  }
  if (rest_lengths.size() != s)
    throw InputError("spring system.rest_lengths", "expected " + std::to_string(s) + " values");
  for (int k = 0; k < s; ++k)
    if (!(rest_lengths[k] > 0.0) || !std::isfinite(rest_lengths[k]))
      throw InputError("spring system.rest_lengths[" + std::to_string(k) + "]",
          "must be > 0, got " + std::to_string(rest_lengths[k]));
  for (int f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (faces(f, c) < 0 || faces(f, c) >= n)
        throw InputError(
            "spring system.faces[" + std::to_string(f) + "]", "node index out of range");

  degree.assign(static_cast<std::size_t>(n), 0);
  for (int k = 0; k < s; ++k) {
    ++degree[static_cast<std::size_t>(springs(k, 0))];
    ++degree[static_cast<std::size_t>(springs(k, 1))];
  }
  incident_offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int a = 0; a < n; ++a)
    incident_offsets[a + 1] = incident_offsets[a] + degree[a];
  incident.assign(static_cast<std::size_t>(2 * s), 0);
  std::vector<int> fill(incident_offsets.begin(), incident_offsets.end() - 1);
  for (int k = 0; k < s; ++k) {
    incident[fill[springs(k, 0)]++] = k;
    incident[fill[springs(k, 1)]++] = k;
  }
}

std::string_view to_string(ClothPlane plane) {
  return plane == ClothPlane::vertical ? "vertical" : "horizontal";
}
std::string_view to_string(ClothPins pins) {
  switch (pins) {
  case ClothPins::top_corners:
    return "top-corners";
  case ClothPins::top_row:
    return "top-row";
  case ClothPins::none:
    return "none";
  }
  return "unknown";
}

ClothPlane cloth_plane_from_string(const std::string& name, const std::string& where) {
  if (name == "vertical")
    return ClothPlane::vertical;
  if (name == "horizontal")
    return ClothPlane::horizontal;
  throw InputError(
      where, "unknown cloth plane '" + name + "' (expected one of: vertical, horizontal)");
}

ClothPins cloth_pins_from_string(const std::string& name, const std::string& where) {
  for (ClothPins p : { ClothPins::top_corners, ClothPins::top_row, ClothPins::none })
    if (to_string(p) == name)
      return p;
  throw InputError(
      where, "unknown pins '" + name + "' (expected one of: top-corners, top-row, none)");
}

SpringSystem make_rope(int nodes, double rest_length, double node_mass) {
  if (nodes < 2)
    throw InputError("rope.nodes", "must be >= 2, got " + std::to_string(nodes));
  if (nodes > kMaxSpringNodes)
    throw InputError("rope.nodes",
        "must be at most " + std::to_string(kMaxSpringNodes) + ", got " + std::to_string(nodes));
  if (!(rest_length > 0.0))
    throw InputError("rope.rest_length", "must be > 0");
  if (!(node_mass > 0.0))
    throw InputError("rope.mass", "must be > 0");
  SpringSystem sys;
  sys.rest = Positions::Zero(nodes, 3);
  for (int a = 0; a < nodes; ++a)
    sys.rest(a, 0) = a * rest_length;
  sys.springs.resize(nodes - 1, 2);
  for (int k = 0; k + 1 < nodes; ++k)
    sys.springs.row(k) << k, k + 1;
  sys.masses = VecX::Constant(nodes, node_mass);
  sys.pinned.assign(static_cast<std::size_t>(nodes), 0);
  sys.pinned[0] = 1;
  sys.finalize();
  return sys;
}

SpringSystem make_cloth(const ClothOptions& o) {
  if (o.columns < 2)
    throw InputError("cloth.columns", "must be >= 2, got " + std::to_string(o.columns));
  if (o.rows < 2)
    throw InputError("cloth.rows", "must be >= 2, got " + std::to_string(o.rows));
  if (double(o.columns) * double(o.rows) > double(kMaxSpringNodes))
    throw InputError("cloth",
        std::to_string(o.columns) + " x " + std::to_string(o.rows) + " nodes is more than "
            + std::to_string(kMaxSpringNodes));
  if (!(o.spacing > 0.0))
    throw InputError("cloth.spacing", "must be > 0");
  if (!(o.node_mass > 0.0))
    throw InputError("cloth.mass", "must be > 0");
  const int nx = o.columns, ny = o.rows, n = nx * ny;
  auto id = [nx](int i, int r) { return r * nx + i; };
  SpringSystem sys;
  sys.rest = Positions::Zero(n, 3);
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      sys.rest(id(i, r), 0) = i * o.spacing;
      if (o.plane == ClothPlane::vertical)
        sys.rest(id(i, r), 1) = -r * o.spacing;
      else
        sys.rest(id(i, r), 2) = r * o.spacing;
    }
  std::vector<std::pair<int, int>> edges;
  for (int r = 0; r < ny; ++r)
    for (int i = 0; i < nx; ++i) {
      if (i + 1 < nx)
        edges.emplace_back(id(i, r), id(i + 1, r));
      if (r + 1 < ny)
        edges.emplace_back(id(i, r), id(i, r + 1));
      if (o.shear && i + 1 < nx && r + 1 < ny) {
        edges.emplace_back(id(i, r), id(i + 1, r + 1));
        edges.emplace_back(id(i + 1, r), id(i, r + 1));
      }
    }
  sys.springs.resize(static_cast<Eigen::Index>(edges.size()), 2);
  for (std::size_t k = 0; k < edges.size(); ++k)
    sys.springs.row(static_cast<Eigen::Index>(k)) << edges[k].first, edges[k].second;
  sys.faces.resize(2 * (nx - 1) * (ny - 1), 3);
  int f = 0;
  for (int r = 0; r + 1 < ny; ++r)
    for (int i = 0; i + 1 < nx; ++i) {
      sys.faces.row(f++) << id(i, r), id(i, r + 1), id(i + 1, r + 1);
      sys.faces.row(f++) << id(i, r), id(i + 1, r + 1), id(i + 1, r);
    }
  sys.masses = VecX::Constant(n, o.node_mass);
  sys.pinned.assign(static_cast<std::size_t>(n), 0);
  if (o.pins == ClothPins::top_corners) {
    sys.pinned[id(0, 0)] = sys.pinned[id(nx - 1, 0)] = 1;
  } else if (o.pins == ClothPins::top_row) {
    for (int i = 0; i < nx; ++i)
      sys.pinned[id(i, 0)] = 1;
  }
  sys.finalize();
  return sys;
}

std::vector<int> cloth_bottom_row(const ClothOptions& o) {
  std::vector<int> out;
  for (int i = 0; i < o.columns; ++i)
    out.push_back((o.rows - 1) * o.columns + i);
  return out;
}

SpringState rest_state(const SpringSystem& system) {
  return { system.rest, Positions::Zero(system.node_count(), 3) };
}

namespace detail {
Positions checked_forces(const SpringSystem& system, const Loads& loads) {
  if (!loads.gravity.allFinite())
    throw InputError("loads.gravity", "non-finite value");
  if (loads.forces.rows() == 0)
    return Positions::Zero(system.node_count(), 3);
  if (loads.forces.rows() != system.node_count())
    throw InputError("loads.forces",
        "expected " + std::to_string(system.node_count()) + " rows, got "
            + std::to_string(loads.forces.rows()));
  if (!loads.forces.allFinite())
    throw InputError("loads.forces", "non-finite value");
  return loads.forces;
}
} // namespace detail

} // namespace elastolearn::springs
