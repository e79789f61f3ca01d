#include <elastolearn/springs/linear_regression.hpp>

#include <elastolearn/core/error.hpp>

#include <Eigen/QR>

#include <cmath>
#include <string>

namespace elastolearn::springs {

void RegressionOptions::validate() const {
  if (!(ridge >= 0.0) || !std::isfinite(ridge))
    throw InputError(
        "regression options", "ridge must be a finite value >= 0, got " + std::to_string(ridge));
}

MatX LinearRegression::predict(ConstRef<MatX> x) const {
  ELASTOLEARN_CHECK(x.cols() == features(), "feature count mismatch in LinearRegression::predict");
  MatX y = x * coefficients.bottomRows(features());
  y.rowwise() += coefficients.row(0);
  return y;
}

LinearRegression fit_linear_regression(
    ConstRef<MatX> x, ConstRef<MatX> y, const RegressionOptions& options) {
  options.validate();
  const Eigen::Index n = x.rows(), p = x.cols(), q = y.cols();
  if (y.rows() != n)
    throw InputError("regression data",
        "feature rows (" + std::to_string(n) + ") and output rows (" + std::to_string(y.rows())
            + ") differ");
  if (!x.allFinite() || !y.allFinite())
    throw InputError("regression data", "non-finite value (NaN or inf) in the samples");
  const Eigen::Index unknowns = p + (options.intercept ? 1 : 0);
  if (n < unknowns && options.ridge == 0.0)
    throw InputError("regression data",
        std::to_string(n) + " samples for " + std::to_string(unknowns) + " unknowns");

  // Centre (intercept) and scale (ridge) the columns; the fit is done on the transformed design
  // and mapped back, so the intercept is never penalised and the ridge acts on standardised β.
  VecX mean_x = VecX::Zero(p), scale = VecX::Ones(p);
  VecX mean_y = VecX::Zero(q);
  if (options.intercept && n > 0) {
    mean_x = x.colwise().mean().transpose();
    mean_y = y.colwise().mean().transpose();
  }
  MatX design = x.rowwise() - mean_x.transpose();
  if (options.ridge > 0.0) {
    for (Eigen::Index j = 0; j < p; ++j) {
      const double s = std::sqrt(design.col(j).squaredNorm() / std::max<Eigen::Index>(n, 1));
      scale[j] = s > 0.0 ? s : 1.0;
      design.col(j) /= scale[j];
    }
  }
  MatX rhs = y.rowwise() - mean_y.transpose();
  if (options.ridge > 0.0) {
    design.conservativeResize(n + p, Eigen::NoChange);
    design.bottomRows(p) = std::sqrt(options.ridge) * MatX::Identity(p, p);
    rhs.conservativeResize(n + p, Eigen::NoChange);
    rhs.bottomRows(p).setZero();
  }
  Eigen::ColPivHouseholderQR<MatX> qr(design);
  LinearRegression fit;
  fit.rank = static_cast<int>(qr.rank());
  if (qr.rank() < p)
    throw InputError("regression data",
        "design matrix is rank deficient (rank " + std::to_string(qr.rank()) + " of "
            + std::to_string(p) + "): the samples do not determine the model");
  const MatX beta = qr.solve(rhs); // p×q on standardised columns
  fit.coefficients.resize(p + 1, q);
  for (Eigen::Index j = 0; j < p; ++j)
    fit.coefficients.row(j + 1) = beta.row(j) / scale[j];
  fit.coefficients.row(0)
      = mean_y.transpose() - mean_x.transpose() * fit.coefficients.bottomRows(p);

  fit.residuals = y - fit.predict(x);
  for (Eigen::Index o = 0; o < q; ++o) {
    const double ss_res = fit.residuals.col(o).squaredNorm();
    const double ss_tot = (y.col(o).array() - y.col(o).mean()).matrix().squaredNorm();
    fit.rms_residual.push_back(std::sqrt(ss_res / std::max<Eigen::Index>(n, 1)));
    fit.r_squared.push_back(ss_tot > 0.0 ? 1.0 - ss_res / ss_tot : (ss_res == 0.0 ? 1.0 : 0.0));
  }
  return fit;
}

} // namespace elastolearn::springs
