#include <elastolearn/springs/feature_map.hpp>

#include <elastolearn/core/error.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::springs {

std::string_view to_string(FeatureKind kind) {
  return kind == FeatureKind::polynomial ? "polynomial" : "spline";
}

FeatureKind feature_kind_from_string(const std::string& name, const std::string& where) {
  if (name == "polynomial")
    return FeatureKind::polynomial;
  if (name == "spline")
    return FeatureKind::spline;
  throw InputError(
      where, "unknown feature map '" + name + "' (expected one of: polynomial, spline)");
}

void FeatureMap::validate() const {
  if (kind == FeatureKind::polynomial) {
    if (degree < 1 || degree > 8)
      throw InputError("features.degree", "must be in 1..8, got " + std::to_string(degree));
  } else {
    if (knots.size() < 2)
      throw InputError("features.knots", "a spline needs at least 2 knots");
    for (std::size_t i = 0; i < knots.size(); ++i) {
      if (!std::isfinite(knots[i]))
        throw InputError("features.knots", "non-finite knot");
      if (i > 0 && !(knots[i] > knots[i - 1]))
        throw InputError(
            "features.knots", "knots must be strictly increasing (knot " + std::to_string(i) + ")");
    }
  }
  if (size() > k_max_features)
    throw InputError("features",
        "too many features (" + std::to_string(size()) + " > " + std::to_string(k_max_features)
            + ")");
}

int FeatureMap::size() const {
  if (kind == FeatureKind::polynomial)
    return (degree + 1) * (degree + 2) / 2 - 1;
  return static_cast<int>(knots.size()) + 1; // hats 1..n−1 (hat 0 = intercept − Σ others), v, e v
}

namespace {
/// Index of the knot interval containing e (clamped to the first/last interval: linear
/// extrapolation outside the knot range).
int spline_interval(const std::vector<double>& knots, double e) {
  const auto it = std::upper_bound(knots.begin(), knots.end(), e);
  const int i = static_cast<int>(it - knots.begin()) - 1;
  return std::clamp(i, 0, static_cast<int>(knots.size()) - 2);
}
} // namespace

void FeatureMap::evaluate(double e, double v, double* out) const {
  if (kind == FeatureKind::polynomial) {
    double pe[9], pv[9];
    pe[0] = pv[0] = 1.0;
    for (int i = 1; i <= degree; ++i) {
      pe[i] = pe[i - 1] * e;
      pv[i] = pv[i - 1] * v;
    }
    int f = 0;
    for (int d = 1; d <= degree; ++d)
      for (int b = 0; b <= d; ++b)
        out[f++] = pe[d - b] * pv[b];
    return;
  }
  // Hats sum to one, so hat 0 is left out (the intercept spans it): feature j−1 is hat j.
  const int n = static_cast<int>(knots.size());
  std::fill(out, out + n - 1, 0.0);
  const int i = spline_interval(knots, e);
  const double t = (e - knots[i]) / (knots[i + 1] - knots[i]);
  if (i > 0)
    out[i - 1] = 1.0 - t;
  out[i] = t;
  out[n - 1] = v;
  out[n] = e * v;
}

void FeatureMap::evaluate_derivatives(double e, double v, double* de, double* dv) const {
  if (kind == FeatureKind::polynomial) {
    double pe[9], pv[9];
    pe[0] = pv[0] = 1.0;
    for (int i = 1; i <= degree; ++i) {
      pe[i] = pe[i - 1] * e;
      pv[i] = pv[i - 1] * v;
    }
    int f = 0;
    for (int d = 1; d <= degree; ++d)
      for (int b = 0; b <= d; ++b) {
        const int a = d - b;
        de[f] = a > 0 ? a * pe[a - 1] * pv[b] : 0.0;
        dv[f] = b > 0 ? b * pe[a] * pv[b - 1] : 0.0;
        ++f;
      }
    return;
  }
  const int n = static_cast<int>(knots.size());
  std::fill(de, de + n + 1, 0.0);
  std::fill(dv, dv + n + 1, 0.0);
  const int i = spline_interval(knots, e);
  const double inv_h = 1.0 / (knots[i + 1] - knots[i]);
  if (i > 0)
    de[i - 1] = -inv_h;
  de[i] = inv_h;
  dv[n - 1] = 1.0;
  de[n] = v;
  dv[n] = e;
}

std::vector<std::string> FeatureMap::names() const {
  std::vector<std::string> out;
  auto power = [](const char* s, int p) {
    if (p == 0)
      return std::string();
    return p == 1 ? std::string(s) : std::string(s) + "^" + std::to_string(p);
  };
  if (kind == FeatureKind::polynomial) {
    for (int d = 1; d <= degree; ++d)
      for (int b = 0; b <= d; ++b) {
        std::string name = power("e", d - b);
        const std::string vp = power("v", b);
        out.push_back(name.empty() ? vp : (vp.empty() ? name : name + " " + vp));
      }
  } else {
    for (std::size_t i = 1; i < knots.size(); ++i)
      out.push_back("hat(e; " + std::to_string(knots[i]) + ")");
    out.emplace_back("v");
    out.emplace_back("e v");
  }
  return out;
}

Eigen::MatrixXd FeatureMap::evaluate_all(const Eigen::Ref<const Eigen::MatrixXd>& states) const {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> phi(states.rows(), size());
  for (Eigen::Index r = 0; r < states.rows(); ++r)
    evaluate(states(r, 0), states(r, 1), phi.row(r).data());
  return phi;
}

std::vector<double> uniform_knots(double lo, double hi, int count) {
  if (count < 2 || !(hi > lo))
    throw InputError("features.knots", "need count >= 2 and hi > lo");
  std::vector<double> knots(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    knots[static_cast<std::size_t>(i)] = lo + (hi - lo) * i / (count - 1);
  return knots;
}

} // namespace elastolearn::springs
