#include "iplan/intent/forecast_calibration.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace iplan::intent {

double EllipsoidCoverage(const Eigen::MatrixXd& errors, const Eigen::MatrixXd& variances,
                         double noise_variance, double scale) {
  const Eigen::Index N = errors.rows();
  if (N == 0) return 0.0;
  long inside = 0;
  for (Eigen::Index i = 0; i < N; ++i) {
    double d2 = 0.0;
    for (Eigen::Index a = 0; a < errors.cols(); ++a) {
      const double e2 = errors(i, a) * errors(i, a);
      const double denom = scale * variances(i, a) + noise_variance;
      d2 += denom > 0.0 ? e2 / denom : (e2 > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
    }
    if (d2 <= kChi2Dof3P95) ++inside;
  }
  return static_cast<double>(inside) / static_cast<double>(N);
}

double CalibrateVarianceScale(const Eigen::MatrixXd& errors, const Eigen::MatrixXd& variances,
                              double noise_variance, double coverage, double min_scale,
                              double max_scale) {
  if (errors.rows() != variances.rows() || errors.cols() != variances.cols()) {
    throw std::invalid_argument("CalibrateVarianceScale: errors (" + std::to_string(errors.rows()) + " x " +
                                std::to_string(errors.cols()) + ") and variances (" +
                                std::to_string(variances.rows()) + " x " + std::to_string(variances.cols()) +
                                ") differ in size");
  }
  if (!(min_scale > 0.0 && min_scale <= max_scale && std::isfinite(max_scale)) ||
      !(coverage > 0.0 && coverage < 1.0) || !(noise_variance >= 0.0)) {
    throw std::invalid_argument("CalibrateVarianceScale: need 0 < min_scale <= max_scale < inf, coverage in "
                                "(0, 1) and noise_variance >= 0");
  }
  // Coverage does not decrease with the scale: bisection on log s.
  if (EllipsoidCoverage(errors, variances, noise_variance, min_scale) >= coverage) return min_scale;
  if (EllipsoidCoverage(errors, variances, noise_variance, max_scale) < coverage) return max_scale;
  double lo = std::log(min_scale), hi = std::log(max_scale);  // coverage(lo) < target <= coverage(hi)
  while (hi - lo > 1e-6) {
    const double mid = 0.5 * (lo + hi);
    (EllipsoidCoverage(errors, variances, noise_variance, std::exp(mid)) >= coverage ? hi : lo) = mid;
  }
  return std::exp(hi);
}

}  // namespace iplan::intent
