#pragma once
/// \file Feature maps of the phase-space state (e, v) for the spring regressor. Degree-1
/// polynomial features (e, v) are the paper's linear model; higher degrees and a piecewise-linear
/// spline basis in e learn nonlinear springs (the paper's §7 future work).
#include <Eigen/Core>

#include <string>
#include <string_view>
#include <vector>

namespace elastolearn::springs {

/// Kind of feature map; one name table for CLI and JSON.
enum class FeatureKind {
  polynomial, ///< all monomials e^a v^b with 1 ≤ a + b ≤ degree (degree 1: the paper's (e, v))
  spline, ///< hat functions of e on `knots` (piecewise-linear in e; the first hat is
          ///< left out because the intercept spans it) plus v and e·v
};

/// "polynomial", "spline".
std::string_view to_string(FeatureKind kind);
/// Inverse of to_string; throws InputError(where, ...).
FeatureKind feature_kind_from_string(const std::string& name, const std::string& where);

/// Upper bound on the number of features (keeps per-spring evaluation allocation-free).
inline constexpr int k_max_features = 64;

/// A feature map φ(e, v) ∈ R^p, evaluated without allocation.
struct FeatureMap {
  FeatureKind kind = FeatureKind::polynomial;
  int degree = 1; ///< polynomial: total degree (1..8)
  std::vector<double> knots; ///< spline: strictly increasing elongations [m], at least 2

  /// Throws InputError("features.<field>", ...) for an invalid degree or knot vector.
  void validate() const;
  /// Number of features p (without the intercept).
  int size() const;
  /// φ(e, v) into out[0..p).
  void evaluate(double e, double v, double* out) const;
  /// ∂φ/∂e and ∂φ/∂v into de[0..p), dv[0..p). At a spline knot, the right derivative.
  void evaluate_derivatives(double e, double v, double* de, double* dv) const;
  /// Human-readable names of the features, e.g. "e^2 v".
  std::vector<std::string> names() const;
  /// Evaluate for many samples: N×2 (e, v) → N×p.
  Eigen::MatrixXd evaluate_all(const Eigen::Ref<const Eigen::MatrixXd>& states) const;
};

/// Uniform knots over [lo, hi] (count ≥ 2).
std::vector<double> uniform_knots(double lo, double hi, int count);

} // namespace elastolearn::springs
