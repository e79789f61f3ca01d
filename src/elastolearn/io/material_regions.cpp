#include <elastolearn/core/error.hpp>
#include <elastolearn/io/material_regions.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace elastolearn::io {

namespace {

int parse_axis(const JsonObject& o) {
  const std::string a = o.choice("axis", { "x", "y", "z" });
  return a[0] - 'x';
}

/// Rest centroids of every tet (m × 3).
Positions rest_centroids(const mesh::TetMesh& mesh) {
  Positions c(mesh.num_tets(), 3);
  for (int e = 0; e < mesh.num_tets(); ++e) {
    Vec3 sum = Vec3::Zero();
    for (int a = 0; a < 4; ++a)
      sum += mesh.rest_positions().row(mesh.tets()(e, a)).transpose();
    c.row(e) = (sum / 4.0).transpose();
  }
  return c;
}

/// The tets whose centroid satisfies `pick(c)`.
template <class Pick> std::vector<int> pick_elements(const Positions& centroids, Pick pick) {
  std::vector<int> out;
  for (Eigen::Index e = 0; e < centroids.rows(); ++e)
    if (pick(Vec3(centroids.row(e).transpose())))
      out.push_back(static_cast<int>(e));
  return out;
}

} // namespace

std::vector<int> select_elements(const JsonObject& o, const mesh::TetMesh& mesh) {
  o.reject_unknown_keys({ "elements", "box", "plane", "layers" });
  if (o.has("elements") + o.has("box") + o.has("plane") + o.has("layers") != 1)
    o.fail("", "an element selection needs exactly one of elements, box, plane, layers");
  if (o.has("elements")) {
    std::vector<int> ids = o.integers("elements");
    for (int i : ids)
      if (i < 0 || i >= mesh.num_tets())
        o.fail("elements",
            "tet " + std::to_string(i) + " out of range [0, " + std::to_string(mesh.num_tets())
                + ")");
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  }
  const Positions centroids = rest_centroids(mesh);
  if (o.has("box")) {
    const JsonObject b = o.object("box");
    b.reject_unknown_keys({ "min", "max" });
    const Vec3 lo = b.vec3("min"), hi = b.vec3("max");
    return pick_elements(centroids, [&](const Vec3& c) {
      return (c.array() >= lo.array()).all() && (c.array() <= hi.array()).all();
    });
  }
  if (o.has("plane")) {
    const JsonObject p = o.object("plane");
    p.reject_unknown_keys({ "axis", "value", "tolerance" });
    const int axis = parse_axis(p);
    const double value = p.number("value");
    const double tolerance = p.number("tolerance");
    if (!(tolerance >= 0))
      p.fail("tolerance", "must be a non-negative distance [m]");
    return pick_elements(
        centroids, [&](const Vec3& c) { return std::abs(c[axis] - value) <= tolerance; });
  }
  const JsonObject l = o.object("layers");
  l.reject_unknown_keys({ "axis", "period", "start", "thickness" });
  const int axis = parse_axis(l);
  const double period = l.positive("period");
  const double start = l.number("start", 0.0);
  const double thickness = l.positive("thickness");
  if (!(thickness < period))
    l.fail("thickness", "must be less than the period (else every element is selected)");
  return pick_elements(centroids, [&](const Vec3& c) {
    const double phase = c[axis] - start - period * std::floor((c[axis] - start) / period);
    return phase < thickness;
  });
}

std::shared_ptr<const std::vector<double>> parse_material_regions(
    const JsonObject& material, const mesh::TetMesh& mesh) {
  const double young = material.positive("young");
  const std::vector<JsonObject> regions = material.objects("regions");
  if (regions.empty())
    material.fail("regions", "is empty: give at least one region, or leave the key out");
  auto scale = std::make_shared<std::vector<double>>(mesh.num_tets(), 1.0);
  for (const JsonObject& region : regions) {
    region.reject_unknown_keys({ "select", "young" });
    const JsonObject selection = region.object("select");
    const std::vector<int> elements = select_elements(selection, mesh);
    if (elements.empty())
      selection.fail("", "selects no element");
    const double region_young = region.positive("young");
    for (int e : elements)
      (*scale)[e] = region_young / young;
  }
  return scale;
}

} // namespace elastolearn::io
