#include <elastolearn/mesh/mesh_validation.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <cmath>

namespace elastolearn::mesh {

namespace {

std::string locate(const std::string& source, const std::vector<int>* lines, int index) {
  if (lines && index < static_cast<int>(lines->size()) && (*lines)[index] > 0)
    return source + ":" + std::to_string((*lines)[index]);
  return source;
}

} // namespace

double six_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, bool& degenerate) {
  const Vec3 e1 = b - a, e2 = c - a, e3 = d - a;
  const double det = e1.dot(e2.cross(e3));
  const double longest = std::sqrt(std::max({ e1.squaredNorm(), e2.squaredNorm(), e3.squaredNorm(),
      (c - b).squaredNorm(), (d - b).squaredNorm(), (d - c).squaredNorm() }));
  degenerate = !(std::abs(det) > kDegenerateTolerance * longest * longest * longest);
  return det;
}

void validate_tet_mesh(
    const Positions& rest, const Tets& tets, const std::string& source, const SourceLines* lines) {
  if (rest.rows() == 0)
    throw InputError(source, "mesh has no vertices");
  if (tets.rows() == 0)
    throw InputError(source, "mesh has no tetrahedra");
  const std::vector<int>* vlines = lines ? &lines->vertex_lines : nullptr;
  const std::vector<int>* tlines = lines ? &lines->tet_lines : nullptr;
  for (Eigen::Index i = 0; i < rest.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(rest(i, k)))
        throw InputError(locate(source, vlines, static_cast<int>(i)),
            "vertex " + std::to_string(i) + " has a non-finite coordinate " + to_text(rest(i, k)));
    }
  }
  const int n = static_cast<int>(rest.rows());
  for (Eigen::Index t = 0; t < tets.rows(); ++t) {
    const auto where = [&] { return locate(source, tlines, static_cast<int>(t)); };
    for (int k = 0; k < 4; ++k) {
      const int v = tets(t, k);
      if (v < 0 || v >= n)
        throw InputError(where(),
            "tet " + std::to_string(t) + " has vertex index " + std::to_string(v)
                + " out of range [0, " + std::to_string(n) + ")");
    }
    bool degenerate = false;
    const double det = six_volume(rest.row(tets(t, 0)), rest.row(tets(t, 1)), rest.row(tets(t, 2)),
        rest.row(tets(t, 3)), degenerate);
    if (degenerate)
      throw InputError(where(),
          "tet " + std::to_string(t) + " is degenerate (rest volume " + to_text(det / 6.0) + ")");
    if (det < 0)
      throw InputError(where(),
          "tet " + std::to_string(t) + " is inverted (negative orientation, rest volume "
              + to_text(det / 6.0) + "); tets must satisfy det[x1-x0, x2-x0, x3-x0] > 0");
  }
}

} // namespace elastolearn::mesh
