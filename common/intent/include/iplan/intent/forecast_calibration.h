// Calibration of the forecast covariances on held-out data.
//
// A forecast of one joint at one future step is a Gaussian with diagonal
// covariance diag(s v_a + n), a = x, y, z: v the model's (SPGP) variance, n
// the sensor-noise variance that is always added (METHOD 3), s >= 0 the
// calibration scale of the model part. Given held-out errors e (truth minus
// predicted mean) with their v, the scale is chosen so that the share of
// errors inside the 95 % ellipsoid, sum_a e_a^2 / (s v_a + n) <= chi2_3(0.95),
// is the target coverage.
#pragma once

#include <Eigen/Core>

namespace iplan::intent {

/// Chi-square quantile with 3 degrees of freedom at 0.95.
inline constexpr double kChi2Dof3P95 = 7.815;

/// Share of rows i with sum_a errors(i, a)^2 / (scale variances(i, a) + noise_variance)
/// <= kChi2Dof3P95. `errors` and `variances` (N, 3), m and m^2; a zero
/// denominator counts as inside only for a zero error. 0 for N = 0.
double EllipsoidCoverage(const Eigen::MatrixXd& errors, const Eigen::MatrixXd& variances,
                         double noise_variance, double scale);

/// The smallest scale s in [min_scale, max_scale] (0 < min_scale <= max_scale)
/// whose EllipsoidCoverage is at least `coverage` (in (0, 1)), to a relative
/// precision of 1e-6: min_scale when the sensor noise alone covers enough,
/// max_scale when even that is not enough. Throws std::invalid_argument on
/// mismatched sizes or invalid bounds. Deterministic; allocates nothing
/// beyond its arguments.
double CalibrateVarianceScale(const Eigen::MatrixXd& errors, const Eigen::MatrixXd& variances,
                              double noise_variance, double coverage, double min_scale,
                              double max_scale);

}  // namespace iplan::intent
