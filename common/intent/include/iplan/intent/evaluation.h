// Evaluation of an intent model on recorded sequences: early-prediction
// accuracy, confusion matrix, forecast error against constant-position and
// constant-velocity baselines on the same windows, 95 % ellipsoid coverage
// and inference time.
//
// The constant-velocity baseline is made as strong as its family allows: the
// velocity (and the position it starts from) is a least-squares line through
// the last L recorded frames (KinematicBaseline with tau = infinity), for
// every L in EvalParams::velocity_frames, and the report gives per horizon
// the L with the lowest error on the evaluated data itself. That choice
// looks at the test data, so it can only favour the baseline.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/intent/coverage_adapter.h"
#include "iplan/intent/intent_model.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::intent {

struct EvalParams {
  /// Observed fractions of each sequence for the accuracy curve, in (0, 1].
  std::vector<double> fractions{0.2, 0.4, 0.6, 0.8, 1.0};
  int forecast_stride = 1;  ///< Frames between evaluated forecast windows (>= 1).
  double max_gap = 0.6;     ///< s, as in TrainParams.
  /// L (>= 1) tried for the least-squares baselines (constant velocity and
  /// the smoothed constant position); 2 is the last-frame velocity.
  std::vector<int> velocity_frames{2, 3, 4, 5, 6, 8, 10, 15};
  /// s (> 0): horizons at which the hand and reaching errors are reported
  /// (JointForecastErrors), interpolated linearly between the model's steps;
  /// those outside [1 / rate, horizon / rate] are left out.
  std::vector<double> report_horizons{0.5, 1.0};
  /// The online calibration of each track's ellipsoids, as the intent
  /// service does it per body (coverage_adapter.h); halving_time = 0 scores
  /// the model's own covariances.
  CoverageAdapterParams coverage;
};

/// Forecast errors of some joints at one reported horizon (m, mean
/// Euclidean distance over the scored (window, joint) pairs). Prediction and
/// truth are interpolated linearly between the two steps around the horizon;
/// the constant-velocity line is evaluated at the horizon itself.
struct HorizonError {
  double horizon_s = 0.0;
  double model = 0.0;           ///< the mixture mean
  double const_position = 0.0;  ///< hold the newest recorded position
  /// The least-squares line through the last L frames, the best L of
  /// EvalParams::velocity_frames on these very pairs (favours the baseline).
  double const_velocity = 0.0;
  int const_velocity_frames = 0;  ///< that L
  /// model / min(const_position, const_velocity); below 1: better than both.
  double RatioToBestBaseline() const;
};

/// Forecasts of a subset of joints over the forecast windows.
struct JointForecastErrors {
  std::vector<std::string> joints;  ///< names of the joints that can be scored
  long num_samples = 0;             ///< (window, joint) pairs scored
  std::vector<HorizonError> at;     ///< per reported horizon
  /// Share of their true future positions, every step, inside the 95 %
  /// ellipsoid of the moment-matched mixture.
  double coverage95 = 0.0;
};

struct EvalReport {
  std::vector<std::string> actions;  ///< (C) model actions.
  int num_sequences = 0;             ///< Classified tracks.
  std::vector<double> fractions;     ///< Observed fractions.
  std::vector<double> accuracy;      ///< Per fraction, share of tracks whose most
                                     ///< probable action is the true one.
  std::vector<double> mean_true_probability;  ///< Per fraction, mean p(true action).
  Eigen::MatrixXi confusion;         ///< (C, C) at the last fraction: row true, column predicted.
  int num_forecast_windows = 0;      ///< Windows with a full recorded future.
  std::vector<double> horizon_s;     ///< (D) seconds ahead of each future step.
  std::vector<double> error_model;   ///< (D) m, mean joint error of the mixture mean.
  std::vector<double> error_const_position;  ///< (D) m, baseline: hold current pose.
  /// (D) m, baseline: extrapolate the least-squares line through the last L
  /// frames, the best L of `velocity_frames` per horizon.
  std::vector<double> error_const_velocity;
  std::vector<int> const_velocity_frames;    ///< (D) that L.
  /// (D) m, diagnostic: hold the least-squares line's current value (the
  /// smoothed current pose), the best L per horizon; the part of a gain over
  /// constant position that mere smoothing gives.
  std::vector<double> error_smoothed_position;
  std::vector<int> smoothed_position_frames;  ///< (D) that L.
  std::vector<int> velocity_frames;           ///< (V) the L tried.
  Eigen::MatrixXd error_const_velocity_by_frames;   ///< (V, D) m, per L tried.
  Eigen::MatrixXd error_smoothed_position_by_frames;  ///< (V, D) m, per L tried.
  double coverage95 = 0.0;           ///< Share of true future joints inside the
                                     ///< moment-matched mixture's 95 % ellipsoid.
  /// The model's hand joints (JointConfig::hands; every model joint when it
  /// names none) in every forecast window.
  JointForecastErrors hand;
  /// Reaching joints (Track::reaching at the window's newest frame, any model
  /// joint): num_samples 0 when the data do not say which joints reach.
  JointForecastErrors reaching;
  double inference_p50_ms = 0.0;     ///< Per PredictIntent call (one frame; accuracy
                                     ///< and forecast windows).
  double inference_p99_ms = 0.0;
  int num_inference_calls = 0;
};

/// Evaluates `model` on every sequence of `data`. Accuracy: for each track
/// and fraction f the model sees the first ceil(f n) frames: the windows of
/// the last T frames ending at every one of them are classified and combined
/// by a BeliefFilter with model.classifier.belief (one update per model
/// frame), as the intent service does online; the belief after frame
/// ceil(f n) is scored against the action of that frame (Track::frame_actions
/// when the track has them, else its label).
/// Forecasts: every window (stride `forecast_stride`) whose true future of
/// `horizon` frames is recorded, as the intent service publishes it: its
/// mixture components weighted by the belief after that frame and their
/// covariances scaled by the track's CoverageAdapter (both run over every
/// frame of the track). The baselines see the recorded frames up to
/// the window's end (no padding). Throws std::invalid_argument when the data
/// lack a model joint, contain an action the model does not know, or when
/// `velocity_frames` is empty or has an entry < 1.
EvalReport EvaluateIntentModel(const IntentModel& model, const SkeletonDataset& data,
                               const EvalParams& params);

/// Machine-readable report: top-level "accuracy" ({"0.2": ..., "1.0": ...}),
/// "error_m" ({"<horizon s>": {"model", "const_position", "const_velocity",
/// "const_velocity_frames", "smoothed_position", "smoothed_position_frames"}}),
/// "const_velocity_by_frames" and "smoothed_position_by_frames" ({"<L>":
/// {"<horizon s>": error}}),
/// "coverage95", "inference_ms" ({"p50", "p99"}), plus "confusion",
/// "actions", "num_sequences", "num_forecast_windows", and "hand" and
/// "reaching" ({"joints", "samples", "coverage95", "error_m": {"<horizon s>":
/// {"model", "const_position", "const_velocity", "const_velocity_frames",
/// "ratio_to_best_baseline"}}}; "reaching" is null without reaching flags).
std::string EvalReportToJson(const EvalReport& report);

/// Human-readable multi-line report.
std::string EvalReportToText(const EvalReport& report);

/// Formats a number as used for the JSON keys: up to 3 significant digits,
/// always with a decimal point ("0.2", "1.0", "0.0667").
std::string FormatKey(double value);

}  // namespace iplan::intent
