// Online calibration of one person's forecast ellipsoids.
//
// The covariances of a trained model are calibrated on its training people
// (forecast_calibration.h): 95 % of their held-out futures fall inside the
// 95 % ellipsoid. A person who moves less (or more) than those people gets
// ellipsoids that are too wide (or too narrow). The adapter watches the
// person's own forecasts come true: every forecast step that matures (its
// time is reached by a new observation) is scored inside or outside its 95 %
// ellipsoid (the moment-matched mixture, as the evaluation scores it), and a
// per-joint variance scale s_j follows the share outside, adaptive conformal
// inference (Gibbs and Candes, "Adaptive conformal inference under
// distribution shift", NeurIPS 2021) on log s_j:
//
//   log s_j += gamma (f_j - (1 - target)),   gamma = ln 2 / ((1 - target) rate t_half),
//
// per observation, f_j being the share of joint j's steps matured at that
// observation that fell outside. With every step inside, s_j halves in
// t_half seconds; steps outside widen it faster. Over a long recording the
// share inside tends to `target` whatever the person (the long-run guarantee
// of adaptive conformal inference), from the first second on only past
// observations are used. s_j is bounded to [min_scale, max_scale].
//
// A new person starts from the scales the cell has learned so far (the
// previous person's, `carry_over`), not from the model's: the cell's camera
// and its people differ from the training people in the same way for
// everyone, and a person tracked for a few seconds would otherwise spend them
// with the model's ellipsoids (on the cell's synthetic person, the hands'
// scales settle at 3-9 within a 17 s episode).
//
// Used with the same parameters by the intent service (per body) and by
// EvaluateIntentModel (per track). Not thread-safe; one instance per person.
#pragma once

#include <deque>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/intent/intent_model.h"

namespace iplan::intent {

struct CoverageAdapterParams {
  /// s (>= 0): with every matured step inside, a joint's variance scale
  /// halves in this time; 0 turns the adaptation off (s_j stays 1).
  double halving_time = 5.0;
  double target = 0.95;    ///< share of matured steps inside, in (0, 1)
  double min_scale = 0.1;  ///< bounds of s_j (0 < min <= 1 <= max)
  double max_scale = 10.0;
  /// true: a new person (or a tracking gap) starts from the scales learned
  /// so far in the cell (Reset(scales) with the last person's); false: from
  /// the model's (1). The owner of the adapters applies it.
  bool carry_over = true;

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

class CoverageAdapter {
 public:
  /// For predictions of `num_joints` joints over `horizon` steps at `rate`
  /// Hz (a model's config). Throws std::invalid_argument on bad sizes or params.
  CoverageAdapter(int num_joints, int horizon, double rate, CoverageAdapterParams params = {});

  /// Forgets the stored forecasts and sets every scale to 1 (the model's).
  void Reset();
  /// Forgets the stored forecasts and starts from `scales` (J), e.g. the
  /// previous person's variance_scales(), clamped to [min_scale, max_scale].
  void Reset(const Eigen::Ref<const Eigen::VectorXd>& scales);

  /// Scores the stored forecasts whose steps mature at time `stamp` (s, not
  /// decreasing between calls) against the observed `positions` (3 J, m,
  /// frame W) and updates the scales. A step matures at an observation within
  /// a quarter step of its time; steps no observation came near are skipped.
  void Observe(double stamp, const Eigen::Ref<const Eigen::VectorXd>& positions);

  /// Multiplies the covariance of joint j, every step and component of
  /// `pred`, by s_j. `pred` must have num_joints joints and horizon steps.
  void Apply(JointMixture* pred) const;

  /// Stores `pred` (as published, after Apply) made at `stamp` for scoring.
  void Record(double stamp, const JointMixture& pred);

  /// (J) the variance scales s_j.
  const Eigen::VectorXd& variance_scales() const { return scale_; }

 private:
  struct Stored {
    double stamp = 0.0;
    int next_step = 0;                    // first step not yet matured or skipped
    std::vector<Eigen::Vector3d> mean;    // (H J) at k * J + j
    std::vector<Eigen::Matrix3d> inverse; // (H J) inverse covariances
  };
  int num_joints_, horizon_;
  double rate_;
  CoverageAdapterParams params_;
  double gain_;
  std::deque<Stored> stored_;
  Eigen::VectorXd log_scale_, scale_;
  Eigen::VectorXd outside_, matured_;  // (J) per Observe
};

}  // namespace iplan::intent
