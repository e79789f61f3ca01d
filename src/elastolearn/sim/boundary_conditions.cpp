#include <elastolearn/core/error.hpp>
#include <elastolearn/sim/boundary_conditions.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace elastolearn::sim {

Vec3 KeyframeMotion::offset_at(double t) const {
  if (kind == Kind::Sinusoid)
    return amplitude * std::sin(2 * std::numbers::pi * frequency * std::min(t, until));
  if (times.empty())
    return Vec3::Zero();
  if (t <= times.front())
    return offsets.front();
  if (t >= times.back())
    return offsets.back();
  const auto k
      = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double s = (t - times[k - 1]) / (times[k] - times[k - 1]);
  return (1 - s) * offsets[k - 1] + s * offsets[k];
}

Vec3 TrackedVertices::position_at(int j, double t) const {
  const double s = (t - start_time) / dt;
  const int last = static_cast<int>(positions.size()) - 1;
  if (s <= 0)
    return positions.front().row(j).transpose();
  if (s >= last)
    return positions.back().row(j).transpose();
  const int k = std::min(static_cast<int>(s), last - 1);
  const double w = s - k;
  // Snap to a recorded frame when t is one (times are sums of steps and carry round-off).
  if (w < 1e-9)
    return positions[k].row(j).transpose();
  if (w > 1 - 1e-9)
    return positions[k + 1].row(j).transpose();
  return ((1 - w) * positions[k].row(j) + w * positions[k + 1].row(j)).transpose();
}

void TrackedVertices::validate(int num_vertices) const {
  if (vertices.empty())
    throw InputError("tracked", "no tracked vertices");
  for (int v : vertices)
    if (v < 0 || v >= num_vertices)
      throw InputError("tracked",
          "vertex index " + std::to_string(v) + " out of range [0, " + std::to_string(num_vertices)
              + ")");
  if (positions.empty())
    throw InputError("tracked", "no recorded frames");
  if (!(dt > 0 && std::isfinite(dt)))
    throw InputError("tracked.dt", "must be a positive number");
  for (size_t k = 0; k < positions.size(); ++k)
    if (positions[k].rows() != static_cast<Eigen::Index>(vertices.size())
        || !positions[k].allFinite())
      throw InputError("tracked",
          "frame " + std::to_string(k) + " must hold " + std::to_string(vertices.size())
              + " finite positions");
}

void KeyframeMotion::validate(int num_vertices) const {
  if (vertices.empty())
    throw InputError("keyframes", "vertex group is empty");
  for (int v : vertices)
    if (v < 0 || v >= num_vertices)
      throw InputError("keyframes",
          "vertex index " + std::to_string(v) + " out of range [0, " + std::to_string(num_vertices)
              + ")");
  if (kind == Kind::Sinusoid && !(frequency > 0 && std::isfinite(frequency)))
    throw InputError("keyframes.frequency", "must be a positive number");
  if (kind == Kind::PiecewiseLinear) {
    if (times.empty() || times.size() != offsets.size())
      throw InputError("keyframes.times", "need as many times as offsets (at least one)");
    for (size_t k = 1; k < times.size(); ++k)
      if (!(times[k] > times[k - 1]))
        throw InputError("keyframes.times", "must be increasing");
  }
}

ExternalLoads::ExternalLoads(
    const VecX& dof_masses, const Vec3& gravity, std::vector<PointLoad> loads)
    : m_gravity_force(dof_masses.size())
    , m_loads(std::move(loads)) {
  for (Eigen::Index v = 0; v < dof_masses.size() / 3; ++v)
    m_gravity_force.segment<3>(3 * v) = dof_masses[3 * v] * gravity;
}

void ExternalLoads::add_force(const fem::ForceState& state, VecX& f) {
  f += m_scale * m_gravity_force;
  for (const auto& load : m_loads) {
    if (state.time >= load.release_time || load.vertices.empty())
      continue;
    const Vec3 share = m_scale * load.total_force / static_cast<double>(load.vertices.size());
    for (int v : load.vertices)
      f.segment<3>(3 * v) += share;
  }
}

} // namespace elastolearn::sim
