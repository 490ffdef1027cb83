// Baseline motion predictors: what a person's future looks like without a
// learned model. They produce the same Gaussian-mixture type as the intent
// model (JointMixture, one component of probability 1), so a planner or
// monitor can take either, and the value of the model can be measured against
// them (`iplan eval interaction`; later also offered by the intent service).
//
//   constant position: every joint stays where it was last observed;
//   constant velocity: every joint keeps the velocity of a least-squares line
//     fitted to its positions over the last `window` seconds (a fit, not a
//     two-frame difference, so that sensor noise does not dominate).
//
// Covariance growth (isotropic, per coordinate, t = (k + 1) / rate the time
// of future step k after the newest observation, sigma_n = sensor_noise_std,
// g_j the joint's growth: joint_growth[j], or the scalar when it is empty):
//   constant position:  var_j(t) = sigma_n^2 + (g_j t)^2,  g = speed_std
//     (the person's speed is unknown: the error grows linearly in time);
//   constant velocity:  var_j(t) = sigma_n^2 + var_fit(t) + (g_j t^2 / 2)^2,  g = acceleration_std
//     with var_fit(t) = sigma_n^2 (1/n + (t - tbar)^2 / S_tt) the variance of
//     the fitted line at t (n frames at times tbar +- ..., S_tt their spread)
//     and the acceleration term for what a constant velocity cannot follow.
// The sigma_n^2 term is the noise of the future observation itself, as the
// intent model adds its sensor noise to every predicted covariance.
// CalibrateBaselineGrowth fits g_j to a predictor's own errors on recorded
// motion (e.g. the demonstrations an intent model is trained on), so that a
// baseline's covariances are as honest as the model's: a torso that hardly
// moves gets a small growth, a working hand a large one.
//
// Frames: positions are metres in the frame of the observations (W); stamps
// are seconds (any epoch). Free functions are thread-safe; BaselinePredictor
// is not (one per tracked body). Both allocate (the output).
#pragma once

#include <deque>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/intent/intent_model.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::intent {

enum class BaselineKind { kConstantPosition, kConstantVelocity };

/// "constant_position" / "constant_velocity": the action label of the
/// prediction's single component.
const char* ToString(BaselineKind kind);

struct BaselinePredictorParams {
  BaselineKind kind = BaselineKind::kConstantVelocity;
  double rate = 15.0;             ///< Hz; future step k is at t0 + (k + 1) / rate
  int horizon = 15;               ///< future steps (>= 1)
  double window = 0.25;           ///< s of history in the velocity fit (> 0)
  double sensor_noise_std = 0.01; ///< m, per coordinate noise of an observation (>= 0)
  double speed_std = 0.25;        ///< m/s, constant position: spread of the unknown speed (>= 0)
  double acceleration_std = 1.0;  ///< m/s^2, constant velocity: unmodelled acceleration (>= 0)
  /// Per joint (J entries, >= 0): speed_std (constant position) or
  /// acceleration_std (constant velocity) of that joint. Empty: the scalar
  /// for every joint.
  std::vector<double> joint_growth;

  /// Empty when valid, else the offending field and value.
  std::string Validate() const;
};

/// Predicts from the recent observations of one person: `stamps` (n >= 1, s,
/// strictly increasing, newest last) and `positions` (n, 3 J; joint j in
/// columns 3j..3j+2, m, W). Frames older than newest - window are ignored by
/// the velocity fit; with a single usable frame constant velocity falls back
/// to constant position (speed unknown). `*out` gets dt = 1 / rate, the
/// horizon, J joints and one component labelled ToString(kind) with
/// probability 1; means and covariances as in the header comment.
/// Throws std::invalid_argument on invalid params, no frames, mismatched
/// sizes, a column count that is not a multiple of 3, stamps that do not
/// increase or non-finite values.
void PredictBaseline(const BaselinePredictorParams& params, const Eigen::VectorXd& stamps,
                     const Eigen::MatrixXd& positions, JointMixture* out);

/// Fits joint_growth for `params` (kind, rate, horizon, window, noise) to the
/// predictor's own errors on `data` (its sequences' frames in any frame,
/// `joints` selecting and ordering the joints; frames where one is not
/// detected are skipped): every frame with a full window of history is
/// predicted from, each step's mean compared with the sequence's position at
/// that time (linear between frames; steps past the end are left out), and
/// per joint the mean squared error per coordinate e_k at step k fitted by
/// least squares, e_k - base_k = g^2 phi_k (phi = t^2, or t^4 / 4 for
/// constant velocity; base the noise and fit terms at the window's nominal
/// frame count), g^2 clamped at 0. Returns g (J). Throws
/// std::invalid_argument on invalid params, an unknown joint or no usable
/// prediction. Thread-safe; allocates.
std::vector<double> CalibrateBaselineGrowth(const BaselinePredictorParams& params, const SkeletonDataset& data,
                                            const std::vector<std::string>& joints);

/// Keeps one person's recent frames and predicts with every new one.
class BaselinePredictor {
 public:
  /// `num_joints` J >= 1. Throws std::invalid_argument on invalid params.
  BaselinePredictor(BaselinePredictorParams params, int num_joints);

  /// Adds the frame observed at `stamp` (s; after the previous one) with
  /// positions (3 J, m, W) and writes the prediction from it to `*out`.
  /// Throws std::invalid_argument on a stamp not after the previous frame,
  /// a wrong size or non-finite values (the history is then unchanged).
  void Update(double stamp, const Eigen::VectorXd& positions, JointMixture* out);
  /// Forgets the history (a new person, or a tracking gap).
  void Reset();
  int buffered_frames() const { return static_cast<int>(stamps_.size()); }
  const BaselinePredictorParams& params() const { return params_; }

 private:
  BaselinePredictorParams params_;
  int num_joints_;
  std::deque<double> stamps_;
  std::deque<Eigen::VectorXd> positions_;
  Eigen::VectorXd stamp_buffer_;
  Eigen::MatrixXd position_buffer_;
};

}  // namespace iplan::intent
