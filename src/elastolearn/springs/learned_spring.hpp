#pragma once
/// \file A spring learned by regression in phase space (paper 004 §3): a model of the one-step
/// map (e, v) → (Δe, Δv) of the 1-D training particle, fitted by least squares with intercept.
#include <elastolearn/springs/feature_map.hpp>
#include <elastolearn/springs/linear_regression.hpp>
#include <elastolearn/springs/training_data.hpp>

namespace elastolearn::springs {

/// Options of `learn_spring`.
struct LearnOptions {
  FeatureMap features; ///< default: polynomial degree 1 = the paper's linear model (e, v)
  double ridge = 0.0; ///< ridge penalty λ (0: ordinary least squares, the paper)
  /// Throws InputError for invalid features or ridge.
  void validate() const;
};

/// Quality of the fit on its training data (the regression's own report).
struct FitReport {
  std::vector<double> r_squared; ///< per output (Δe, Δv)
  std::vector<double> rms_residual; ///< per output [m, m/s]
  std::vector<double> max_residual; ///< per output, max |y − ŷ|
  int samples = 0;
};

/// The learned spring: features φ, coefficients B ((p+1)×2, intercept in row 0, columns Δe, Δv),
/// and the training particle's dt and mass. It is the only spring model of the learned
/// simulators: they call `predict` (paper mode) or `force` / `force_slopes` (corrected modes).
///
/// The learned force is the impulse the spring gave the training particle over one step,
/// f(e, v) = m·Δv̂(e, v)/dt — exact for data from semi-implicit Euler, whose Δv = dt·f(e, v)/m.
class LearnedSpring {
  public:
  LearnedSpring() = default;
  /// Throws InputError if the coefficient shape does not match the features or dt, mass ≤ 0.
  LearnedSpring(
      FeatureMap features, MatX coefficients, double dt, double mass, FitReport report = {});

  /// Predicted (Δe, Δv) over one training step dt (paper Eq. 3 when linear).
  Vec2 predict(double e, double v) const;
  /// Learned spring force on the particle along +e [N]: m·Δv̂/dt.
  double force(double e, double v) const;
  /// Force and its slopes ∂f/∂e [N/m], ∂f/∂v [N s/m] (for the implicit mode).
  void force_slopes(double e, double v, double& f, double& df_de, double& df_dv) const;

  const FeatureMap& features() const { return m_features; }
  /// (p+1)×2, intercept row 0; column 0 predicts Δe, column 1 predicts Δv.
  const MatX& coefficients() const { return m_coefficients; }
  double dt() const { return m_dt; }
  double mass() const { return m_mass; }
  const FitReport& report() const { return m_report; }
  /// True for degree-1 polynomial features (the paper's linear model).
  bool is_linear() const { return m_linear; }

  private:
  FeatureMap m_features;
  MatX m_coefficients;
  double m_dt = 0.01;
  double m_mass = 1.0;
  FitReport m_report;
  bool m_linear = true;
  // Linear fast path: Δe = a0 + a1 e + a2 v, Δv = b0 + b1 e + b2 v.
  double m_a[3] = { 0, 0, 0 };
  double m_b[3] = { 0, 0, 0 };
  // Δv coefficients of the features (column 1 without the intercept), contiguous.
  std::vector<double> m_dv_coefficients;
  double m_b0 = 0.0; // Δv intercept
};

/// Fit a learned spring to a training set (paper §3: least squares with intercept).
/// Throws InputError for invalid options or data that do not determine the model.
LearnedSpring learn_spring(const TrainingSet& data, const LearnOptions& options = {});

/// Convenience: generate the paper's data for `training` and fit `options`.
LearnedSpring learn_spring(const TrainingOptions& training, const LearnOptions& options = {});

} // namespace elastolearn::springs
