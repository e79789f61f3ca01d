#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/correction_curves.hpp>
#include <elastolearn/material/correction.hpp>
#include <elastolearn/material/damping_model.hpp>
#include <elastolearn/material/elastic_model.hpp>

#include <algorithm>
#include <cmath>
#include <functional>

namespace elastolearn::learn {

namespace {

Vec3 sorted_descending(Vec3 s) {
  std::sort(s.data(), s.data() + 3, std::greater<>());
  return s;
}

void check_range(double low, double high, int samples) {
  if (!(low > 0) || !(high > low) || !std::isfinite(high) || samples < 2) {
    throw InputError("stretch path",
        "needs 0 < low < high and at least 2 samples, got " + std::to_string(low) + ", "
            + std::to_string(high) + ", " + std::to_string(samples));
  }
}

template <typename Stretches>
StretchPath path_over(
    std::string label, double low, double high, int samples, const Stretches& stretches) {
  StretchPath path { std::move(label), {}, {} };
  path.x.reserve(static_cast<std::size_t>(samples));
  path.stretches.reserve(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const double x = low + (high - low) * i / (samples - 1);
    path.x.push_back(x);
    path.stretches.push_back(sorted_descending(stretches(x)));
  }
  return path;
}

} // namespace

StretchPath uniaxial_path(double low, double high, int samples) {
  check_range(low, high, samples);
  return path_over("uniaxial stretch", low, high, samples, [](double s) { return Vec3(s, 1, 1); });
}

std::vector<StretchPath> deformation_scale_paths(double max_scale, int samples) {
  if (!(max_scale > 0) || !(max_scale < 1) || samples < 2) {
    throw InputError("stretch path",
        "needs a deformation scale in (0, 1) and at least 2 samples, got "
            + std::to_string(max_scale) + ", " + std::to_string(samples));
  }
  const struct {
    const char* label;
    Vec3 direction;
  } directions[]
      = { { "uniaxial tension", Vec3(1, 0, 0) }, { "uniaxial compression", Vec3(-1, 0, 0) },
          { "equibiaxial tension", Vec3(1, 1, 0).normalized() },
          { "equibiaxial compression", Vec3(-1, -1, 0).normalized() },
          { "volumetric expansion", Vec3(1, 1, 1).normalized() },
          { "volumetric compression", Vec3(-1, -1, -1).normalized() } };
  std::vector<StretchPath> paths;
  for (const auto& d : directions) {
    paths.push_back(path_over(d.label, 0, max_scale, samples,
        [&](double scale) { return Vec3(Vec3::Ones() + scale * d.direction); }));
  }
  return paths;
}

StretchPath largest_stretch_path(double low, double high, int samples) {
  check_range(low, high, samples);
  return path_over("largest stretch", low, high, samples,
      [](double s) { return s >= 1 ? Vec3(s, 1, 1) : Vec3(s, s, s); });
}

std::vector<Vec3> stress_difference(const StretchPath& path, const fem::MaterialModel& model,
    const material::ElasticModel& reference) {
  std::vector<Vec3> out;
  out.reserve(path.stretches.size());
  for (const Vec3& s : path.stretches) {
    Vec3 p = model.elastic->principal_stress(s) - reference.principal_stress(s);
    if (model.correction)
      p += model.correction->correction(s, Vec3::Zero());
    out.push_back(p);
  }
  return out;
}

std::vector<double> stiffness_damping(const StretchPath& path, const fem::MaterialModel& model) {
  std::vector<double> out;
  out.reserve(path.stretches.size());
  for (const Vec3& s : path.stretches) {
    const double alpha1 = model.damping ? model.damping->coefficients(s[0]).alpha1 : 0.0;
    out.push_back(material::corrected_stiffness_damping(alpha1, model.correction.get(), s));
  }
  return out;
}

std::vector<bool> inside(const StretchPath& path, const material::StretchRange& range) {
  std::vector<bool> out;
  out.reserve(path.stretches.size());
  for (const Vec3& s : path.stretches)
    out.push_back(!range.empty() && range.contains(s, 0));
  return out;
}

} // namespace elastolearn::learn
