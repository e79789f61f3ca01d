#include <elastolearn/springs/learned_spring.hpp>

#include <elastolearn/core/error.hpp>

#include <cmath>

namespace elastolearn::springs {

void LearnOptions::validate() const {
  features.validate();
  RegressionOptions { true, ridge }.validate();
}

LearnedSpring::LearnedSpring(
    FeatureMap features, MatX coefficients, double dt, double mass, FitReport report)
    : m_features(std::move(features))
    , m_coefficients(std::move(coefficients))
    , m_dt(dt)
    , m_mass(mass)
    , m_report(std::move(report)) {
  m_features.validate();
  if (m_coefficients.rows() != m_features.size() + 1 || m_coefficients.cols() != 2)
    throw InputError("learned spring.coefficients",
        "expected " + std::to_string(m_features.size() + 1) + "x2 coefficients, got "
            + std::to_string(m_coefficients.rows()) + "x" + std::to_string(m_coefficients.cols()));
  if (!m_coefficients.allFinite())
    throw InputError("learned spring.coefficients", "non-finite coefficient");
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("learned spring.dt", "must be > 0, got " + std::to_string(dt));
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw InputError("learned spring.mass", "must be > 0, got " + std::to_string(mass));
  m_linear = m_features.kind == FeatureKind::polynomial && m_features.degree == 1;
  m_b0 = m_coefficients(0, 1);
  m_dv_coefficients.resize(static_cast<std::size_t>(m_features.size()));
  for (int j = 0; j < m_features.size(); ++j)
    m_dv_coefficients[j] = m_coefficients(j + 1, 1);
  if (m_linear)
    for (int i = 0; i < 3; ++i) {
      m_a[i] = m_coefficients(i, 0);
      m_b[i] = m_coefficients(i, 1);
    }
}

Vec2 LearnedSpring::predict(double e, double v) const {
  if (m_linear)
    return { m_a[0] + m_a[1] * e + m_a[2] * v, m_b[0] + m_b[1] * e + m_b[2] * v };
  double phi[k_max_features];
  m_features.evaluate(e, v, phi);
  Vec2 y(m_coefficients(0, 0), m_coefficients(0, 1));
  for (int j = 0; j < m_features.size(); ++j) {
    y[0] += m_coefficients(j + 1, 0) * phi[j];
    y[1] += m_coefficients(j + 1, 1) * phi[j];
  }
  return y;
}

double LearnedSpring::force(double e, double v) const {
  if (m_linear)
    return (m_b[0] + m_b[1] * e + m_b[2] * v) * (m_mass / m_dt);
  const double* b = m_dv_coefficients.data();
  double y = m_b0;
  if (m_features.kind == FeatureKind::polynomial) {
    // Same monomial order as FeatureMap::evaluate, without materialising the features.
    const int degree = m_features.degree;
    double pe[9], pv[9];
    pe[0] = pv[0] = 1.0;
    for (int i = 1; i <= degree; ++i) {
      pe[i] = pe[i - 1] * e;
      pv[i] = pv[i - 1] * v;
    }
    for (int d = 1; d <= degree; ++d)
      for (int k = 0; k <= d; ++k)
        y += *b++ * pe[d - k] * pv[k];
    return y * (m_mass / m_dt);
  }
  double phi[k_max_features];
  m_features.evaluate(e, v, phi);
  for (int j = 0, p = m_features.size(); j < p; ++j)
    y += b[j] * phi[j];
  return y * (m_mass / m_dt);
}

void LearnedSpring::force_slopes(
    double e, double v, double& f, double& df_de, double& df_dv) const {
  const double scale = m_mass / m_dt;
  if (m_linear) {
    f = (m_b[0] + m_b[1] * e + m_b[2] * v) * scale;
    df_de = m_b[1] * scale;
    df_dv = m_b[2] * scale;
    return;
  }
  double phi[k_max_features], de[k_max_features], dv[k_max_features];
  m_features.evaluate(e, v, phi);
  m_features.evaluate_derivatives(e, v, de, dv);
  double y = m_coefficients(0, 1), ye = 0.0, yv = 0.0;
  for (int j = 0; j < m_features.size(); ++j) {
    const double b = m_dv_coefficients[j];
    y += b * phi[j];
    ye += b * de[j];
    yv += b * dv[j];
  }
  f = y * scale;
  df_de = ye * scale;
  df_dv = yv * scale;
}

LearnedSpring learn_spring(const TrainingSet& data, const LearnOptions& options) {
  options.validate();
  const MatX phi = options.features.evaluate_all(data.inputs);
  const LinearRegression fit
      = fit_linear_regression(phi, data.outputs, RegressionOptions { true, options.ridge });
  FitReport report;
  report.r_squared = fit.r_squared;
  report.rms_residual = fit.rms_residual;
  for (Eigen::Index o = 0; o < fit.residuals.cols(); ++o)
    report.max_residual.push_back(fit.residuals.col(o).cwiseAbs().maxCoeff());
  report.samples = static_cast<int>(data.inputs.rows());
  return LearnedSpring(options.features, fit.coefficients, data.dt, data.mass, report);
}

LearnedSpring learn_spring(const TrainingOptions& training, const LearnOptions& options) {
  return learn_spring(generate_training_set(training), options);
}

} // namespace elastolearn::springs
