#include "iplan/collision/bound.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace iplan::collision {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kLog2Pi = 1.8378770664093454836;  // log(2 pi)

// Solves sum_i d_i^2 / (1 + lambda s_i)^2 = R^2 for lambda > 0, given
// ||d|| > R and s_i > 0. Newton's method on psi(lambda) = 1/||y(lambda)||:
// y_i = (d_i/s_i) / (1/s_i + lambda) is the trust-region step of a convex
// quadratic with Hessian diag(1/s_i), for which psi is concave and increasing
// (More & Sorensen 1983), so Newton started left of the root (psi < 1/R) stays
// left and converges monotonically and quadratically. Rounding can break that
// near the root, hence the bracket and the bisection fallback.
//
// Bracket: ||d|| / (1 + lambda s_max) <= ||y(lambda)|| <= ||d|| / (1 + lambda
// s_min), so lambda* lies in [(||d||/R - 1)/s_max, (||d||/R - 1)/s_min].
inline double SolveSecular(const Eigen::Vector3d& d, const Eigen::Vector3d& s,
                           double dist, double R, int* iterations) {
  const double excess = dist / R - 1.0;
  double lo = excess / s[2];
  double hi = excess / s[0];
  // Sharper lower end: ||y|| >= |d_i| / (1 + lambda s_i) for each i.
  for (int i = 0; i < 3; ++i) lo = std::max(lo, (std::abs(d[i]) / R - 1.0) / s[i]);
  const double inv_R = 1.0 / R;
  double lambda = lo;
  int it = 0;
  for (; it < 100; ++it) {
    double phi = 0.0;
    double w = 0.0;  // sum s_i y_i^2 t_i = -phi'/2
    for (int i = 0; i < 3; ++i) {
      const double t = 1.0 / (1.0 + lambda * s[i]);
      const double y = d[i] * t;
      phi += y * y;
      w += s[i] * y * y * t;
    }
    const double psi = 1.0 / std::sqrt(phi);
    if (psi < inv_R) {
      lo = lambda;
    } else if (psi > inv_R) {
      hi = lambda;
    } else {
      break;  // exact root
    }
    const double dpsi = psi * psi * psi * w;  // psi' = phi^{-3/2} w > 0
    const double step = (inv_R - psi) / dpsi;
    double next = lambda + step;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double change = std::abs(next - lambda);
    lambda = next;
    // Quadratic convergence: after a step of relative size 1e-8 the error is
    // of order 1e-16 relative, so no confirming step is needed.
    if (change <= 1e-8 * lambda || hi - lo <= 4.0 * kEps * hi) {
      ++it;
      break;
    }
  }
  if (iterations != nullptr) *iterations = it;
  return lambda;
}

}  // namespace

bool FactorizeGaussian(const Eigen::Vector3d& mean, const Eigen::Matrix3d& sigma,
                       FactorizedGaussian* out) {
  if (!mean.allFinite() || !sigma.allFinite()) return false;
  // Lower triangle only; the iterative solver is accurate for condition
  // numbers far beyond what a human-pose covariance has.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sigma, Eigen::ComputeEigenvectors);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::Vector3d s = eig.eigenvalues();
  if (!(s[0] > 0.0) || !(s[0] > 1e-14 * s[2])) return false;
  out->mean = mean;
  out->eigenvectors = eig.eigenvectors();
  out->eigenvalues = s;
  out->inverse = out->eigenvectors * s.cwiseInverse().asDiagonal() *
                 out->eigenvectors.transpose();
  out->log_peak_density =
      -1.5 * kLog2Pi - 0.5 * (std::log(s[0]) + std::log(s[1]) + std::log(s[2]));
  return true;
}

double EvaluatePairLogBound(const FactorizedGaussian& g, const Eigen::Vector3d& b,
                            double R) {
  const Eigen::Vector3d d = g.eigenvectors.transpose() * (g.mean - b);
  const double dist2 = d.squaredNorm();
  const double log_volume = std::log(BallVolume(R));
  if (dist2 <= R * R) return log_volume + g.log_peak_density;
  const Eigen::Vector3d& s = g.eigenvalues;
  const double lambda = SolveSecular(d, s, std::sqrt(dist2), R, nullptr);
  // x - mu in the eigenbasis is -d_i lambda s_i / (1 + lambda s_i); its
  // Mahalanobis norm is computed without cancellation.
  double maha = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double t = lambda / (1.0 + lambda * s[i]);
    maha += d[i] * d[i] * t * t * s[i];
  }
  return log_volume + g.log_peak_density - 0.5 * maha;
}

PairBound EvaluatePairBound(const FactorizedGaussian& g, const Eigen::Vector3d& b,
                            double R) {
  PairBound out;
  const Eigen::Vector3d d = g.eigenvectors.transpose() * (g.mean - b);
  const double dist2 = d.squaredNorm();
  const double log_volume = std::log(BallVolume(R));
  if (dist2 <= R * R) {
    out.x_max = g.mean;
    out.lambda = 0.0;
    out.log_bound = log_volume + g.log_peak_density;
  } else {
    const Eigen::Vector3d& s = g.eigenvalues;
    out.lambda = SolveSecular(d, s, std::sqrt(dist2), R, &out.iterations);
    Eigen::Vector3d y;
    double maha = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double den = 1.0 + out.lambda * s[i];
      y[i] = d[i] / den;
      const double t = out.lambda / den;
      maha += d[i] * d[i] * t * t * s[i];
    }
    out.x_max = b + g.eigenvectors * y;
    out.log_bound = log_volume + g.log_peak_density - 0.5 * maha;
  }
  out.bound = out.log_bound >= 0.0 ? 1.0 : std::exp(out.log_bound);
  return out;
}

PairBound EvaluatePairBoundReferenceBisection(const FactorizedGaussian& g,
                                              const Eigen::Vector3d& b, double R,
                                              const ReferenceBisectionOptions& options) {
  PairBound out;
  const double log_volume = std::log(BallVolume(R));
  const Eigen::Matrix3d& P = g.inverse;  // Sigma^-1
  const Eigen::Vector3d Pmu = P * g.mean;
  auto x_of = [&](double lambda) -> Eigen::Vector3d {
    const Eigen::Matrix3d A = P + lambda * Eigen::Matrix3d::Identity();
    return A.ldlt().solve(Pmu + lambda * b);
  };
  if ((g.mean - b).norm() <= R) {
    out.x_max = g.mean;
  } else {
    double lo = 0.0;
    double hi = 1.0;
    int it = 0;
    while ((x_of(hi) - b).norm() >= R && it < options.max_iterations) {
      lo = hi;
      hi *= 2.0;
      ++it;
    }
    while (hi - lo > options.relative_tolerance * hi && it < options.max_iterations) {
      const double mid = 0.5 * (lo + hi);
      if ((x_of(mid) - b).norm() > R) {
        lo = mid;
      } else {
        hi = mid;
      }
      ++it;
    }
    out.lambda = 0.5 * (lo + hi);
    out.iterations = it;
    out.x_max = x_of(out.lambda);
  }
  const Eigen::Vector3d e = out.x_max - g.mean;
  out.log_bound = log_volume + g.log_peak_density - 0.5 * e.dot(P * e);
  out.bound = out.log_bound >= 0.0 ? 1.0 : std::exp(out.log_bound);
  return out;
}

}  // namespace iplan::collision
