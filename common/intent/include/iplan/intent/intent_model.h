// The intent model: action classification (IVM with a DTW kernel, METHOD 2)
// and per-action future-motion forecasting (SPGP, METHOD 3), combined into a
// Gaussian mixture over actions.
//
// Frames: W is the world (sensor) frame of the skeleton input; all positions
// are metres in W, all times seconds. A "window" is the last frames of one
// person at the model rate, a (n, 3 J) matrix, oldest row first, joint j in
// columns 3j..3j+2, joints in IntentModelConfig::joints.joints order.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/joint_mixture.h"
#include "iplan/intent/belief_filter.h"
#include "iplan/intent/features.h"
#include "iplan/intent/ivm.h"
#include "iplan/intent/kinematic_baseline.h"
#include "iplan/intent/skeleton_data.h"
#include "iplan/intent/sparse_gp.h"

namespace iplan::intent {

/// What a model is built for; stored in the model file and checked on load.
struct IntentModelConfig {
  JointConfig joints;             ///< Joint set, torso reference, hands, objects.
  double rate = 15.0;             ///< Model frame rate, Hz (> 0).
  int window = 15;                ///< T: frames per window (>= 2).
  int horizon = 15;               ///< D: future frames predicted (>= 1).
  int velocity_frames = 2;        ///< Finite-difference span for velocities (>= 1).
  /// Forecaster input: each joint's displacement since this many earlier rows
  /// of the window, evenly spaced back to the oldest (FeatureLayout::
  /// ForecastInput; 0 <= n < window). Model files before format 4: 0.
  int history_samples = 3;
  int dtw_band = 3;               ///< Sakoe-Chiba band half-width, frames (>= 0).
  FrameFeatureOptions features;   ///< Classifier frame-feature options.
  double sensor_noise_std = 0.01; ///< m, isotropic, added to every predicted covariance.

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

/// Training options (not needed at run time).
struct TrainParams {
  double max_gap = 0.6;  ///< s: longer recording gaps split a sequence.
  /// Early prediction: classifier training samples are the windows ending at
  /// these fractions of each training sequence (in (0, 1]).
  std::vector<double> prefix_fractions{0.2, 0.4, 0.6, 0.8, 1.0};
  /// Kernel widths tried in cross-validation, as multiples of the median DTW
  /// distance between training windows.
  std::vector<double> sigma_factors{0.5, 1.0, 2.0};
  /// IVM regularisers tried in cross-validation.
  std::vector<double> lambdas{1e-4, 1e-3, 1e-2};
  IvmParams ivm;  ///< IVM options; `lambda` is replaced by the CV choice.
  /// Whether the classifier is also trained on the mirror images of the
  /// training windows (FeatureLayout::MirroredWindow: the same motion with the
  /// other hand), tried in the leave-one-subject-out cross-validation jointly
  /// with (sigma, lambda). `true` is only tried when the joint set can be
  /// mirrored (a left/right pair, no task objects) and there are two or more
  /// subjects; without cross-validation the first entry is used.
  std::vector<bool> mirror_augmentation{false, true};
  /// Belief-filter time constants tau (s, >= 0, may be +infinity) tried in
  /// leave-one-subject-out cross-validation at the chosen (sigma, lambda):
  /// per held-out training track the filter runs over the windows ending at
  /// every frame, scored (mean log-loss of the belief) at `prefix_fractions`.
  /// Without cross-validation (fewer than two subjects or one entry) the
  /// first entry is used. 0 = classify the last window only.
  std::vector<double> belief_time_constants{0.0, 0.25, 0.5, 1.0, 2.0, 4.0,
                                            std::numeric_limits<double>::infinity()};
  double belief_min_probability = 1e-3;  ///< BeliefFilterParams::min_probability.
  /// BeliefFilterParams::motion_weighted values tried in the same
  /// cross-validation (jointly with the time constants); without
  /// cross-validation the first entry is used.
  std::vector<bool> belief_motion_weighting{false, true};
  int pseudo_inputs = 20;          ///< M per action.
  /// Forecaster design (see ForecastSettings), chosen on the training data
  /// only. The kinematic baseline (L, tau) minimises the mean joint error of
  /// the extrapolation alone over the forecaster training windows of all
  /// actions (nothing is fitted, so no hold-out is needed); these are the
  /// grids. L values above the window length T are skipped.
  std::vector<int> baseline_smoothing_frames{1, 2, 3, 4, 5, 6, 8, 10};
  std::vector<double> baseline_damping_time_constants{
      0.0, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, std::numeric_limits<double>::infinity()};
  /// Residual weights w in [0, 1] tried in cross-validation (0: the
  /// kinematic baseline alone, 1: baseline + the full SPGP residual).
  std::vector<double> residual_weights{0.0, 0.25, 0.5, 0.75, 1.0};
  /// Scale the predicted covariances (SPGP variance plus sensor noise) so
  /// that 95 % of the held-out training futures fall inside the 95 %
  /// ellipsoid, per future step and joint (CalibrateVarianceScale, scales in
  /// [1e-2, 1e4]: at least a tenth of the uncalibrated standard deviation).
  bool calibrate_covariance = true;
  /// ForecastSettings::motion_offset values tried (m/s, > 0, may be
  /// +infinity = no activity scaling), each with its own calibration; the one
  /// with the lowest held-out Gaussian negative log-likelihood is kept.
  std::vector<double> motion_offsets{0.01, 0.02, 0.05, 0.1, 0.2,
                                     std::numeric_limits<double>::infinity()};
  /// Folds of the forecaster cross-validation: the training subjects, or with
  /// one subject its sequences (trials), dealt round-robin into at most this
  /// many folds (>= 2). With fewer than two groups there is no
  /// cross-validation: w = 1 and no
  /// calibration.
  int forecast_cv_folds = 5;
  int forecast_stride = 2;         ///< Frames between forecaster training windows.
  int max_forecast_windows = 600;  ///< Per action, seeded random subset beyond this.
  /// Actions with fewer full-horizon windows than this also use windows whose
  /// future runs past the end of the recording, holding the last pose (short
  /// clips such as Florence 3D).
  int min_forecast_windows = 20;
  int gp_iterations = 150;         ///< L-BFGS iterations per action.
  std::uint64_t seed = 1;
  /// Threads for the classifier's leave-one-subject-out folds (one fold per
  /// thread at a time); 0: one per hardware thread. The model does not
  /// depend on it (each fold is fitted alone, the folds' sums are added in
  /// fold order).
  int threads = 0;

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

/// Classifier part of a model.
struct ActionClassifier {
  double sigma = 1.0;                          ///< DTW kernel width, m.
  std::vector<Eigen::MatrixXd> import_windows; ///< (q) each (F, T): frame features as columns.
  IvmModel ivm;                                ///< q import samples, C classes.
  /// How successive windows of one person are combined (BeliefFilter); the
  /// time constant is the cross-validated choice.
  BeliefFilterParams belief;
};

/// Forecaster of one action: standardisation plus the SPGP.
/// Outputs p = (k * J + j) * 3 + axis: residual of joint j at future step
/// k + 1 about the kinematic extrapolation (ForecastSettings::baseline) of
/// the window, m, frame W. (With the baseline L = 1, tau = 0 of format-2
/// files this is the displacement from the current position.)
struct ActionForecaster {
  Eigen::VectorXd input_mean, input_scale;    ///< (D_in)
  Eigen::VectorXd output_mean, output_scale;  ///< (horizon * 3 J)
  SparseGp gp;
  int num_training_windows = 0;
};

/// How the per-action SPGPs become forecasts (one setting for the model).
/// For joint j at future step k (k = 0: one frame ahead) of action c:
///   mean       = b_kj + w (output_mean + output_scale * SPGP mean)_ckj,
///   covariance = s_kj rho_j^2 (SPGP variance * output_scale^2 + sensor_noise_std^2)
///                (diagonal, per axis; forecast_calibration.h),
/// with b the kinematic extrapolation of the window and rho_j the joint's
/// activity: rho_j = (u_j + m0) / (ubar_j + m0), u_j its mean speed over the
/// window (MeanJointSpeeds), ubar_j the mean of u_j over the training windows
/// and m0 the motion offset (rho = 1 when m0 is infinite). A person who moves
/// more than the training person gets wider ellipsoids. Chosen at training
/// time on the training data only (TrainParams); a format-2 model file is
/// read as L = 1, tau = 0, w = 1, s = 1, m0 = infinity (its forecasters
/// predicted the displacement from the current pose, uncalibrated).
struct ForecastSettings {
  KinematicBaseline baseline;     ///< b: the extrapolation the SPGPs correct.
  double residual_weight = 1.0;   ///< w in [0, 1].
  /// (horizon * J) s_kj > 0 at index k * J + j; empty means all 1.
  Eigen::VectorXd variance_scale;
  /// m0, m/s (> 0, may be +infinity: no activity scaling).
  double motion_offset = std::numeric_limits<double>::infinity();
  /// (J) ubar_j, m/s (>= 0); may be empty when motion_offset is infinite.
  Eigen::VectorXd reference_speed;

  /// Empty string when valid for `horizon` steps of `num_joints` joints,
  /// else the offending field and value.
  std::string Validate(int horizon, int num_joints) const;
};

/// A trained model. Plain data, immutable once trained or loaded; const use
/// from several threads is safe.
struct IntentModel {
  IntentModelConfig config;
  std::vector<std::string> actions;            ///< (C) action labels.
  ActionClassifier classifier;
  std::vector<ActionForecaster> forecasters;   ///< (C), same order as actions.
  ForecastSettings forecast;
};

/// The prediction for one window: a Gaussian mixture over actions, the
/// cell's one prediction type (iplan/collision/joint_mixture.h).
using collision::JointGaussian;
using collision::JointMixture;

/// Summary of a training run (for the CLI).
struct TrainReport {
  int num_classifier_samples = 0;
  int num_import_vectors = 0;
  double median_dtw = 0.0;
  double sigma = 0.0;
  double lambda = 0.0;
  /// One row per (mirror, sigma, lambda) tried: mirror images used (0/1),
  /// sigma, lambda, CV mean log-loss, CV accuracy.
  std::vector<std::array<double, 5>> cv_table;
  bool mirror_augmentation = false;  ///< The chosen: trained on mirror images too.
  double belief_time_constant = 0.0;
  bool belief_motion_weighted = false;
  /// One row per belief setting tried: motion weighted (0/1), tau (s), CV mean
  /// log-loss, CV accuracy.
  std::vector<std::array<double, 4>> belief_cv_table;
  /// The chosen belief filter's cross-validated accuracy at each of
  /// TrainParams::prefix_fractions (empty without cross-validation).
  std::vector<double> belief_cv_accuracy_by_prefix;
  std::vector<int> forecast_windows;  ///< Per action.
  std::vector<bool> forecast_padded;  ///< Per action: held-last-pose futures used.
  /// Kinematic baseline choice: one row per (L, tau) tried: L, tau (s), mean
  /// joint error over all steps on the training windows (m).
  std::vector<std::array<double, 3>> baseline_table;
  KinematicBaseline baseline;        ///< The chosen one.
  double error_const_position = 0.0; ///< m, same windows, holding the last pose.
  int forecast_cv_folds = 0;         ///< 0: no forecaster cross-validation.
  int forecast_cv_windows = 0;       ///< Held-out windows scored.
  /// One row per residual weight tried: w, held-out mean joint error (m) at
  /// the step nearest 0.5 s, at the last step, over all steps.
  std::vector<std::array<double, 4>> residual_cv_table;
  double residual_weight = 1.0;      ///< The chosen w.
  /// Held-out 95 % coverage of the chosen w before and after calibration
  /// (after: on the same held-out windows, so 0.95 by construction up to ties).
  double cv_coverage_raw = 0.0;
  double cv_coverage_calibrated = 0.0;
  double variance_scale_min = 1.0, variance_scale_median = 1.0, variance_scale_max = 1.0;
  /// One row per motion offset tried: m0 (m/s), held-out mean Gaussian
  /// negative log-likelihood per joint and step after calibration, held-out
  /// coverage after calibration.
  std::vector<std::array<double, 3>> motion_cv_table;
  double motion_offset = std::numeric_limits<double>::infinity();  ///< The chosen m0.
  double seconds_classifier = 0.0;
  double seconds_forecaster = 0.0;
};

/// Trains a model on `data` (its subjects are the cross-validation folds).
/// Throws std::invalid_argument for invalid config/params, a model joint
/// missing from the data (the message names it), or fewer than two actions.
/// Any valid JointConfig works, including one joint without a torso.
/// Deterministic for a given seed, whatever TrainParams::threads.
IntentModel TrainIntentModel(const SkeletonDataset& data,
                             const IntentModelConfig& config,
                             const TrainParams& params,
                             TrainReport* report = nullptr);

/// Resamples every sequence of `data` to the model joints and rate.
/// Throws std::invalid_argument naming the first model joint missing from the
/// data.
std::vector<Track> MakeTracks(const SkeletonDataset& data,
                              const IntentModelConfig& config, double max_gap);

/// Class probabilities (C) for a window (n >= 1 rows, 3 J columns, frame W);
/// windows shorter than T are padded at the front, longer ones use the last T
/// rows. Throws std::invalid_argument on a wrong column count, no rows or
/// non-finite values. Thread-safe.
Eigen::VectorXd ClassifyWindow(const IntentModel& model, const Eigen::MatrixXd& window);

/// Full prediction (classification + per-action forecast) for a window (as
/// in ClassifyWindow). The action probabilities are those of this window
/// alone; to combine successive windows of one person feed them to a
/// BeliefFilter built with model.classifier.belief (as the evaluation and
/// the intent service do) and use its probabilities. Fills the actions, the
/// probabilities, the joint names (the model's), time_step (1 / rate),
/// num_steps (the horizon) and the Gaussians; t0_ns is the caller's. Reuses
/// the storage in `out`. Throws as ClassifyWindow.
/// Thread-safe.
void PredictIntent(const IntentModel& model, const Eigen::MatrixXd& window,
                   JointMixture* out);

}  // namespace iplan::intent
