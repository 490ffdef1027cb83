// Kinematic extrapolation of joint positions: a least-squares line through
// the newest frames of a window, extrapolated with a velocity that decays
// exponentially.
//
// For the newest L rows x_0 .. x_{L-1} of a window at `rate` Hz (newest row
// last, at time 0, row i at t_i = (i - L + 1) / rate), the least-squares line
// x(t) = p + v t gives the smoothed current position p and velocity v (per
// column). The extrapolation to t > 0 is
//
//   b(t) = p + v g(t),   g(t) = tau (1 - exp(-t / tau)),
//
// the path of a velocity decaying with time constant tau: tau = 0 holds the
// smoothed position, tau = infinity is constant velocity (g(t) = t). L = 1 is
// the newest row itself with v = 0 (hold the last pose).
//
// This is both the constant-velocity baseline of the evaluation (tau =
// infinity) and the kinematic part of the forecaster, whose SPGP predicts the
// residual of the true future about b(t) (METHOD 3; see docs/intent.md).
#pragma once

#include <string>

#include <Eigen/Core>

namespace iplan::intent {

/// Parameters of the extrapolation (plain data).
struct KinematicBaseline {
  /// L: rows of the least-squares line fit (>= 1; clamped to the rows
  /// available). 1: the newest row, zero velocity.
  int smoothing_frames = 1;
  /// tau, s (>= 0, may be +infinity): decay time constant of the extrapolated
  /// velocity. 0: hold the smoothed position; infinity: constant velocity.
  double damping_time_constant = 0.0;

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

/// Least-squares line through the newest min(frames, n) rows of `rows`
/// (n >= 1, d columns, newest row last) sampled at `rate` Hz (> 0): its value
/// at the newest row's time (d, same unit as the rows) and its slope (d, unit
/// per second; zero when only one row is used). Resizes the outputs to d;
/// does not allocate when they already have size d. Thread-safe.
void FitLine(const Eigen::Ref<const Eigen::MatrixXd>& rows, int frames, double rate,
             Eigen::VectorXd* position, Eigen::VectorXd* velocity);

/// g(t) = tau (1 - exp(-t / tau)) for t >= 0 s: t when tau is infinite, 0
/// when tau is 0.
double DampedDisplacement(double t, double tau);

/// Extrapolated positions (horizon, d) of `window` (n >= 1 rows, d columns,
/// newest last, `rate` Hz): row k is b((k + 1) / rate) for the line fitted by
/// FitLine(window, baseline.smoothing_frames, rate). Resizes `out`; does not
/// allocate when `out` already has that size. Thread-safe.
void ExtrapolateKinematic(const Eigen::Ref<const Eigen::MatrixXd>& window,
                          const KinematicBaseline& baseline, double rate, int horizon,
                          Eigen::MatrixXd* out);

/// Mean speed of each joint over a window (n rows of 3 J columns, newest
/// last, `rate` Hz): for joint j (columns 3j..3j+2) the path length
/// sum_r |x_j(r + 1) - x_j(r)| times rate / (n - 1), m/s. Repeated (padding)
/// rows add nothing; zero for n < 2. Resizes `speeds` to J; does not allocate
/// when it already has that size. Thread-safe.
void MeanJointSpeeds(const Eigen::Ref<const Eigen::MatrixXd>& window, double rate,
                     Eigen::VectorXd* speeds);

}  // namespace iplan::intent
