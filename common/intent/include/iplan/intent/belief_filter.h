// Accumulates class evidence over successive classifier windows of one
// person (METHOD 2, early prediction).
//
// The classifier sees one window of the last T frames. A window alone is
// weak evidence when it covers little motion (e.g. the person standing still
// at the end of an action), so the belief combines the log-probabilities of
// all windows seen so far, the older ones exponentially forgotten:
//
//   b_c(t)  proportional to  exp( sum_i w_i log max(p_i,c, p_min) / sum_i w_i ),
//   w_i = exp(-(t - t_i) / tau) * m_i,
//
// where m_i = 1, or, with `motion_weighted`, m_i = max(WindowMotion(window_i),
// 1e-6 m): windows in which the person hardly moves (standing still after the
// action, or the padded windows at the start of a track) count little, and
// the windows covering the motion count most.
//
// While fewer than T frames have been observed, the newest window holds the
// whole observed history and every earlier window is a part of it; combining
// them would count the first frames again and again with less context. Such a
// partial window therefore replaces the belief (UpdateWithWindow restarts the
// filter); accumulation starts with the first full window, from when on frames
// leave the newest window and older windows carry evidence it lacks.
//
// a weighted geometric mean of the per-window distributions (a product of
// experts, normalised by the total weight so that its calibration does not
// grow with the number or rate of updates). tau = 0 keeps only the newest
// window (the plain window classifier); tau = infinity weighs every window of
// the track equally. The same filter is used by the evaluation (one update per
// model frame) and by the online estimator (one update per skeleton frame;
// the weights depend on time, not on the update rate).
#pragma once

#include <limits>
#include <string>

#include <Eigen/Core>

namespace iplan::intent {

struct BeliefFilterParams {
  /// tau, s (>= 0, may be +infinity): time constant of the forgetting of
  /// older windows' evidence. Chosen at training time by leave-one-subject-out
  /// cross-validation on the training subjects (TrainParams::belief_time_constants).
  double time_constant = 0.0;
  /// p_min in (0, 1): floor of each window's class probabilities before the
  /// logarithm, so one confident wrong window cannot veto a class for ever.
  double min_probability = 1e-3;
  /// Weight each window by its motion (WindowMotion); chosen by the same
  /// cross-validation (TrainParams::belief_motion_weighting).
  bool motion_weighted = false;

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

/// Motion in a window (rows of 3 J joint positions, m, oldest first): the
/// mean over joints of the path length sum_r |x_j(r + 1) - x_j(r)|, m.
/// Repeated (padding) rows add nothing. 0 for fewer than two rows.
double WindowMotion(const Eigen::MatrixXd& window);

/// Not thread-safe; one instance per tracked person. Update does not allocate
/// once the filter has seen its first update.
class BeliefFilter {
 public:
  /// Throws std::invalid_argument when num_classes < 1 or params are invalid.
  explicit BeliefFilter(int num_classes, BeliefFilterParams params = BeliefFilterParams{});

  /// Forgets all evidence (e.g. a new person or a tracking gap).
  void Reset();

  /// Adds one window's class probabilities p (C, entries >= 0) observed at
  /// time `stamp` (s, any epoch; must not decrease between updates). Throws
  /// std::invalid_argument on a wrong size, non-finite entries or a stamp
  /// going backwards.
  /// `weight` (> 0, finite) scales this window's evidence (m_i above; 1 by
  /// default).
  void Update(const Eigen::VectorXd& p, double stamp, double weight = 1.0);

  /// Update for a classified window of observed frames (rows of 3 J
  /// positions, m, oldest first, NOT padded; at most `full_rows` = T rows
  /// are used by the classifier). A window with fewer than `full_rows` rows
  /// (the whole observed history) restarts the filter first. The weight is
  /// WindowMotion(window) (floored at 1e-6 m) when motion_weighted, else 1.
  void UpdateWithWindow(const Eigen::VectorXd& p, const Eigen::MatrixXd& window, int full_rows,
                        double stamp);

  /// Current belief (C), sums to 1; uniform before the first update.
  const Eigen::VectorXd& probabilities() const { return belief_; }
  /// Index of the most probable class.
  int MostLikely() const;
  int num_updates() const { return num_updates_; }
  const BeliefFilterParams& params() const { return params_; }

 private:
  BeliefFilterParams params_;
  Eigen::VectorXd log_sum_;  // (C) sum_i w_i log p_i, weights relative to the newest update
  double weight_sum_ = 0.0;  // sum_i w_i
  double last_stamp_ = 0.0;
  int num_updates_ = 0;
  Eigen::VectorXd belief_;   // (C)
};

}  // namespace iplan::intent
