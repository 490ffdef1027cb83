// The probabilistic collision bound of METHOD.md section 4 for one robot
// sphere against one human sphere whose centre is Gaussian.
//
// For a robot sphere with centre b and radius r1 and a human sphere with
// centre c ~ N(mu, Sigma) and radius r2, the two spheres meet iff
// ||c - b|| <= R with R = r1 + r2, and
//
//   P(||c - b|| <= R) <= V(R) f(x_max),   V(R) = 4/3 pi R^3,
//
// where f is the density of c and x_max the maximiser of f over the closed
// ball B(b, R). The bound is clamped to [0, 1].
//
// x_max: if ||mu - b|| <= R then x_max = mu (lambda = 0). Otherwise x_max lies
// on the sphere, x(lambda) = (Sigma^-1 + lambda I)^-1 (Sigma^-1 mu + lambda b)
// with the unique lambda > 0 such that ||x(lambda) - b|| = R. With
// Sigma = V diag(s) V^T and d = V^T (mu - b), the offset in the eigenbasis is
// y_i(lambda) = d_i / (1 + lambda s_i), so lambda solves the secular equation
// sum_i d_i^2 / (1 + lambda s_i)^2 = R^2 in one variable.
//
// Usage in batched code: factorise each human sphere's covariance once
// (FactorizeGaussian) and evaluate it against many robot spheres
// (EvaluatePairBound). Neither allocates.
#pragma once

#include <Eigen/Core>

namespace iplan::collision {

/// A Gaussian N(mu, Sigma) in R^3 prepared for repeated bound evaluation.
/// Plain data; all quantities in the world frame W, SI units (m, m^2).
struct FactorizedGaussian {
  /// Mean mu (m).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  /// Orthonormal eigenvectors of Sigma as columns, Sigma = V diag(s) V^T.
  Eigen::Matrix3d eigenvectors = Eigen::Matrix3d::Identity();
  /// Eigenvalues s of Sigma, ascending, all > 0 (m^2).
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Ones();
  /// 1 / eigenvalues (1/m^2).
  Eigen::Vector3d inverse_eigenvalues = Eigen::Vector3d::Ones();
  /// Sigma^-1 (1/m^2), kept for the reference implementation and checks.
  Eigen::Matrix3d inverse = Eigen::Matrix3d::Identity();
  /// log of the density's peak value, -3/2 log(2 pi) - 1/2 log det Sigma.
  double log_peak_density = 0.0;
};

/// Factorises Sigma (eigendecomposition) and fills `out`.
/// @param mean   mu (m), world frame.
/// @param sigma  3x3 covariance (m^2); only its lower triangle is read, so the
///               caller must pass a symmetric matrix.
/// @param out    result; must not be null.
/// @returns false (and leaves `out` unspecified) if sigma is not finite or not
///          positive definite (smallest eigenvalue <= 1e-14 * largest, or <= 0).
/// Thread-safe (pure function); does not allocate.
bool FactorizeGaussian(const Eigen::Vector3d& mean, const Eigen::Matrix3d& sigma,
                       FactorizedGaussian* out);

/// Result of one robot-sphere/human-sphere bound.
struct PairBound {
  /// clamp(V(R) f(x_max), 0, 1): upper bound on the probability of contact.
  double bound = 0.0;
  /// log(V(R) f(x_max)) before clamping (may exceed 0).
  double log_bound = 0.0;
  /// Maximiser of the density over the ball B(b, R) (m), world frame.
  Eigen::Vector3d x_max = Eigen::Vector3d::Zero();
  /// Lagrange multiplier (1/m^2); 0 when the mean is inside the ball.
  double lambda = 0.0;
  /// Root-finding iterations used (0 when the mean is inside the ball).
  int iterations = 0;
};

/// Volume 4/3 pi R^3 of a ball of radius R (m^3).
inline double BallVolume(double radius) {
  return 4.0 / 3.0 * 3.14159265358979323846 * radius * radius * radius;
}

/// Evaluates the bound for a robot sphere (centre `b`, world frame, m) against
/// the human sphere `g` with combined radius `R` = r_robot + r_human (m, > 0).
/// Solves the secular equation with Newton-type steps (Halley's method, cubic;
/// Newton's where Halley's denominator is small) on psi = 1/||y(lambda)||,
/// which is concave and increasing, started left of the root from analytic
/// lower bounds, inside the certified bracket [0, (||d||/R - 1)/s_min] with
/// bisection whenever a step leaves it. Converges to machine precision
/// (relative residual of ||x_max - b|| = R below 1e-15) in 2-3 iterations.
/// Thread-safe; does not allocate.
PairBound EvaluatePairBound(const FactorizedGaussian& g, const Eigen::Vector3d& b,
                            double R);

/// Same bound, but only returns log(V(R) f(x_max)); the fast path used by
/// batched evaluation. Thread-safe; does not allocate.
double EvaluatePairLogBound(const FactorizedGaussian& g, const Eigen::Vector3d& b,
                            double R);

/// Batched form of EvaluatePairLogBound for one human sphere against n robot
/// spheres: b is 3 x n (centres, m, W), R[n] the combined radii (m), and
/// log_bounds[n] receives the results. Same arithmetic per pair as
/// EvaluatePairLogBound, but solves 2 pairs at a time so that their
/// division/square-root chains can overlap. `log_volumes`, if not null, holds
/// log(BallVolume(R[k])) for each k (the radii are model constants, so batched
/// callers compute these once); otherwise they are computed here.
/// Thread-safe; does not allocate.
void EvaluatePairLogBounds(const FactorizedGaussian& g,
                           const Eigen::Ref<const Eigen::Matrix3Xd>& b, const double* R,
                           double* log_bounds, const double* log_volumes = nullptr);

/// Options of the reference bisection.
struct ReferenceBisectionOptions {
  /// Stop when the bracket on lambda is narrower than this times its upper end.
  double relative_tolerance = 1e-13;
  /// Hard cap on bisection steps (each halves the bracket).
  int max_iterations = 400;
};

/// Reference implementation as in the source text: bisection on lambda in the
/// world frame, forming x(lambda) = (Sigma^-1 + lambda I)^-1 (Sigma^-1 mu +
/// lambda b) with a 3x3 solve at every step, bracket grown by doubling until
/// ||x(lambda) - b|| < R. For tests and benchmarks only (slow).
/// Uses g.inverse and g.log_peak_density; R as in EvaluatePairBound.
/// Thread-safe; does not allocate.
PairBound EvaluatePairBoundReferenceBisection(
    const FactorizedGaussian& g, const Eigen::Vector3d& b, double R,
    const ReferenceBisectionOptions& options = {});

}  // namespace iplan::collision
