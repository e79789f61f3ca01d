#include <elastolearn/mesh/primitives.hpp>

#include <elastolearn/core/error.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace elastolearn::mesh {

namespace {

/// The 6 axis orders of a Kuhn cell: tet p walks from the cell's start corner along axes
/// kPerm[p][0], kPerm[p][1], kPerm[p][2] to the opposite corner.
constexpr int kPerm[6][3]
    = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };

/// Kuhn lattice on a grid of (cells+1) vertices per axis with the given vertex coordinates.
/// `dir[axis][i]` ∈ {+1, −1} is the direction of the cell diagonal along `axis` in cell slab i;
/// any per-axis choice is conforming because the diagonal of a face normal to one axis depends
/// only on the two other axes' choices, which both neighbours share.
TetMesh kuhn_lattice(const std::array<std::vector<double>, 3>& coords,
    const std::array<std::vector<int>, 3>& dir, const std::string& source) {
  const std::array<int, 3> nv { static_cast<int>(coords[0].size()),
    static_cast<int>(coords[1].size()), static_cast<int>(coords[2].size()) };
  const auto index = [&](int i, int j, int k) { return i + nv[0] * (j + nv[1] * k); };
  Positions rest(static_cast<Eigen::Index>(nv[0]) * nv[1] * nv[2], 3);
  for (int k = 0; k < nv[2]; ++k)
    for (int j = 0; j < nv[1]; ++j)
      for (int i = 0; i < nv[0]; ++i)
        rest.row(index(i, j, k)) << coords[0][i], coords[1][j], coords[2][k];

  const std::array<int, 3> nc { nv[0] - 1, nv[1] - 1, nv[2] - 1 };
  Tets tets(static_cast<Eigen::Index>(6) * nc[0] * nc[1] * nc[2], 4);
  Eigen::Index t = 0;
  for (int k = 0; k < nc[2]; ++k)
    for (int j = 0; j < nc[1]; ++j)
      for (int i = 0; i < nc[0]; ++i) {
        const std::array<int, 3> cell { i, j, k };
        std::array<int, 3> start {}, step {};
        for (int a = 0; a < 3; ++a) {
          step[a] = dir[a][static_cast<std::size_t>(cell[a])];
          start[a] = step[a] > 0 ? cell[a] : cell[a] + 1;
        }
        for (const auto& perm : kPerm) {
          std::array<int, 3> p = start;
          std::array<int, 4> v {};
          v[0] = index(p[0], p[1], p[2]);
          for (int s = 0; s < 3; ++s) {
            p[perm[s]] += step[perm[s]];
            v[s + 1] = index(p[0], p[1], p[2]);
          }
          if (signed_volume(rest.row(v[0]), rest.row(v[1]), rest.row(v[2]), rest.row(v[3])) < 0)
            std::swap(v[1], v[2]);
          tets.row(t++) << v[0], v[1], v[2], v[3];
        }
      }
  return TetMesh(std::move(rest), std::move(tets), source);
}

} // namespace

TetMesh make_box_bar(const Vec3& size, const std::array<int, 3>& cells) {
  std::array<std::vector<double>, 3> coords;
  std::array<std::vector<int>, 3> dir;
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(size[a]) && size[a] > 0))
      throw InputError("make_box_bar",
          "size[" + std::to_string(a) + "] must be positive, got " + std::to_string(size[a]));
    if (cells[a] < 1)
      throw InputError("make_box_bar",
          "cells[" + std::to_string(a) + "] must be >= 1, got " + std::to_string(cells[a]));
  }
  // In double: the product of three ints can overflow 64 bits' worth of care, not a double's.
  const double tets = 6.0 * cells[0] * double(cells[1]) * double(cells[2]);
  if (tets > double(kMaxGeneratedTets))
    throw InputError("make_box_bar",
        "6 x " + std::to_string(cells[0]) + " x " + std::to_string(cells[1]) + " x "
            + std::to_string(cells[2]) + " tets is more than a generated mesh may have ("
            + std::to_string(kMaxGeneratedTets) + ")");
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i <= cells[a]; ++i)
      coords[a].push_back(size[a] * i / cells[a]);
    dir[a].assign(static_cast<std::size_t>(cells[a]), 1);
  }
  return kuhn_lattice(coords, dir, "box bar");
}

TetMesh make_sphere(double radius, int target_tets) {
  if (!(std::isfinite(radius) && radius > 0))
    throw InputError("make_sphere", "radius must be positive, got " + std::to_string(radius));
  if (target_tets < 1)
    throw InputError("make_sphere", "target_tets must be >= 1, got " + std::to_string(target_tets));
  if (target_tets > kMaxGeneratedTets)
    throw InputError("make_sphere",
        "target_tets " + std::to_string(target_tets) + " is more than a generated mesh may have ("
            + std::to_string(kMaxGeneratedTets) + ")");
  // Cells per axis a ≤ b ≤ c ≤ a+1 with 6abc closest to the target (relative error); consecutive
  // candidates differ by a factor ≤ 1.5 for a ≥ 2, so the best one is within ±30 %.
  std::array<int, 3> n { 2, 2, 2 };
  double best = std::numeric_limits<double>::infinity();
  for (int a = 2; 6.0 * a * a * a <= 2.0 * target_tets || a == 2; ++a)
    for (int extra = 0; extra < 3; ++extra) {
      const std::array<int, 3> c { a, a + (extra >= 2 ? 1 : 0), a + (extra >= 1 ? 1 : 0) };
      const double count = 6.0 * c[0] * c[1] * c[2];
      const double err = std::abs(std::log(count / target_tets));
      if (err < best)
        best = err, n = c;
    }
  std::array<std::vector<double>, 3> coords;
  std::array<std::vector<int>, 3> dir;
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i <= n[a]; ++i)
      coords[a].push_back(-1.0 + 2.0 * i / n[a]);
    for (int i = 0; i < n[a]; ++i) {
      const double centre = -1.0 + (2.0 * i + 1.0) / n[a];
      dir[a].push_back(centre < -1e-12 ? -1 : 1); // diagonals point away from the centre
    }
  }
  const TetMesh cube = kuhn_lattice(coords, dir, "sphere");
  Positions rest = cube.rest_positions();
  for (Eigen::Index i = 0; i < rest.rows(); ++i) {
    const Vec3 p = rest.row(i);
    const double l2 = p.norm();
    if (l2 > 0)
      rest.row(i) = radius * p * (p.cwiseAbs().maxCoeff() / l2);
  }
  return TetMesh(std::move(rest), cube.tets(), "sphere");
}

} // namespace elastolearn::mesh
