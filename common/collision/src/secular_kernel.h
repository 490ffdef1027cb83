// Internal: the secular-equation kernel shared by bound.cc and
// trajectory_bound.cc. Not part of the public API.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace iplan::collision::internal {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// The starting point and certified bracket [lo, hi] of every lane (see
// SolveSecularLanes).
template <int L>
inline void StartSecularLanes(const double (&d)[3][L], const double (&s)[3][L], const double (&inv_s)[3][L],
                              const double (&dist)[L], const double (&R)[L], const bool (&need)[L],
                              double (&lambda)[L], double (&lo)[L], double (&hi)[L], double (&inv_R)[L],
                              bool (&active)[L]) {
  for (int l = 0; l < L; ++l) {
    inv_R[l] = 1.0 / R[l];
    const double excess = dist[l] * inv_R[l] - 1.0;
    double low = excess * inv_s[2][l];
    for (int i = 0; i < 3; ++i) {
      low = std::max(low, (std::abs(d[i][l]) * inv_R[l] - 1.0) * inv_s[i][l]);
    }
    // psi is concave, so it lies below its tangent at 0: the tangent's root
    // (a Newton step from 0) is another lower bound.
    const double w0 = s[0][l] * d[0][l] * d[0][l] + s[1][l] * d[1][l] * d[1][l] +
                      s[2][l] * d[2][l] * d[2][l];
    low = std::max(low, dist[l] * dist[l] * excess / w0);
    // The estimates above are exact bounds only in exact arithmetic (they
    // can be tight, e.g. for isotropic Sigma, and rounding may put them on
    // the wrong side), so the certified bracket is [0, hi] with hi padded;
    // `low` is only the starting point.
    lo[l] = 0.0;
    hi[l] = (excess * (1.0 + 1e-6) + 4.0 * kEps * dist[l] * inv_R[l]) * inv_s[0][l];
    low = std::min(low, hi[l]);
    lambda[l] = need[l] ? low : 0.0;
    active[l] = need[l];
  }
}

// Solves sum_i d_i^2 / (1 + lambda s_i)^2 = R^2 for lambda > 0, given
// ||d|| > R and s_i > 0. Newton's method on psi(lambda) = 1/||y(lambda)||:
// y_i = (d_i/s_i) / (1/s_i + lambda) is the trust-region step of a convex
// quadratic with Hessian diag(1/s_i), for which psi is concave and increasing
// (More & Sorensen 1983), so Newton started left of the root (psi < 1/R) stays
// left and converges monotonically and quadratically. Rounding can break that
// near the root, hence the bracket and the bisection fallback.
//
// Bracket: ||d|| / (1 + lambda s_max) <= ||y(lambda)|| <= ||d|| / (1 + lambda
// s_min), so lambda* lies in [(||d||/R - 1)/s_max, (||d||/R - 1)/s_min]; the
// lower end is sharpened with ||y|| >= |d_i| / (1 + lambda s_i) for each i
// and is the starting point (left of the root, where Newton is monotone).
//
// The iteration is Halley's method on psi - 1/R (cubic convergence; Newton's
// step where Halley's denominator is small), written with one square root and
// one division on the critical path; any step that leaves the bracket is
// replaced by bisection.
//
// L independent problems ("lanes") are solved together: their dependency
// chains (divisions, square roots) interleave, so a batch runs at throughput
// rather than latency. Each lane does exactly the arithmetic of L = 1.
// need[l] false marks a lane with the mean inside the ball (lambda = 0).
// inv_s holds 1/s_i (precomputed per Gaussian, saves divisions).
template <int L>
inline void SolveSecularLanes(const double (&d)[3][L], const double (&s)[3][L],
                              const double (&inv_s)[3][L], const double (&dist)[L],
                              const double (&R)[L], const bool (&need)[L],
                              double (&lambda)[L], int* iterations) {
  double lo[L], hi[L], inv_R[L];
  bool active[L];
  StartSecularLanes(d, s, inv_s, dist, R, need, lambda, lo, hi, inv_R, active);
  int it = 0;
  for (; it < 100; ++it) {
    for (int l = 0; l < L; ++l) {
      const double lam = lambda[l];
      double phi = 0.0;  // ||y||^2
      double w = 0.0;    // -phi'/2 = sum s_i y_i^2 t_i
      double v = 0.0;    // phi''/6 = sum s_i^2 y_i^2 t_i^2
      // t_i = 1/(1 + lambda s_i) from one division.
      const double a0 = 1.0 + lam * s[0][l];
      const double a1 = 1.0 + lam * s[1][l];
      const double a2 = 1.0 + lam * s[2][l];
      const double r = 1.0 / (a0 * a1 * a2);
      const double t0 = a1 * a2 * r, t1 = a0 * a2 * r, t2 = a0 * a1 * r;
      const double y0 = d[0][l] * t0, y1 = d[1][l] * t1, y2 = d[2][l] * t2;
      const double st0 = s[0][l] * t0, st1 = s[1][l] * t1, st2 = s[2][l] * t2;
      const double q0 = y0 * y0, q1 = y1 * y1, q2 = y2 * y2;
      phi = q0 + q1 + q2;
      w = st0 * q0 + st1 * q1 + st2 * q2;
      v = st0 * st0 * q0 + st1 * st1 * q1 + st2 * st2 * q2;
      const double norm = std::sqrt(phi);
      const double new_lo = norm > R[l] ? lam : lo[l];
      const double new_hi = norm < R[l] ? lam : hi[l];
      // Halley step on f = psi - 1/R: with a = phi (sqrt(phi)/R - 1) the
      // Newton step is a / w, and f''/(2 f') = 1.5 (w/phi - v/w), giving
      // step = a phi w / (phi w^2 + 1.5 a (w^2 - v phi)) (one division).
      // Where the Halley denominator is small, take the Newton step.
      const double a = phi * (norm * inv_R[l] - 1.0);
      const double pw2 = phi * w * w;
      const double den = pw2 + 1.5 * a * (w * w - v * phi);
      const bool halley = den > 0.25 * pw2;
      // Branch-free selects so that the lane loop vectorises.
      double next = lam + (halley ? a * phi * w : a) / (halley ? den : w);
      const bool in_bracket = (next >= new_lo) & (next <= new_hi);
      next = in_bracket ? next : 0.5 * (new_lo + new_hi);
      next = norm == R[l] ? lam : next;  // exact root
      // Cubic convergence: after a step of relative size 1e-5 the error is of
      // order C 1e-15 relative, so no confirming step is needed (checked:
      // max relative residual | ||y|| - R | / R = 8e-16 over 200,000 random
      // cases with eigenvalue ratios up to 1,000).
      const bool done = (std::abs(next - lam) <= 1e-5 * next) |
                        (new_hi - new_lo <= 4.0 * kEps * new_hi) | (norm == R[l]);
      const bool act = active[l];
      lo[l] = act ? new_lo : lo[l];
      hi[l] = act ? new_hi : hi[l];
      lambda[l] = act ? next : lam;
      active[l] = act & !done;
    }
    bool any = false;
    for (int l = 0; l < L; ++l) any = any || active[l];
    if (!any) {
      ++it;
      break;
    }
  }
  if (iterations != nullptr) *iterations = it;
}

// log(V(R) f(x(lambda))): x - mu in the eigenbasis is -d_i lambda s_i /
// (1 + lambda s_i); its Mahalanobis norm is computed without cancellation.
inline double LogBoundAt(const double (&d)[3], const double (&s)[3], double lambda,
                         double log_volume, double log_peak) {
  const double a0 = 1.0 + lambda * s[0];
  const double a1 = 1.0 + lambda * s[1];
  const double a2 = 1.0 + lambda * s[2];
  const double r = lambda / (a0 * a1 * a2);
  const double ts[3] = {a1 * a2 * r, a0 * a2 * r, a0 * a1 * r};  // lambda / a_i
  double maha = 0.0;
  for (int i = 0; i < 3; ++i) maha += d[i] * d[i] * ts[i] * ts[i] * s[i];
  return log_volume + log_peak - 0.5 * maha;
}

}  // namespace iplan::collision::internal
