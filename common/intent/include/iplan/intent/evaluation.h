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
/// ceil(f n) is scored.
/// Forecasts: every window (stride `forecast_stride`) whose true future of
/// `horizon` frames is recorded. The baselines see the recorded frames up to
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
/// "actions", "num_sequences", "num_forecast_windows".
std::string EvalReportToJson(const EvalReport& report);

/// Human-readable multi-line report.
std::string EvalReportToText(const EvalReport& report);

/// Formats a number as used for the JSON keys: up to 3 significant digits,
/// always with a decimal point ("0.2", "1.0", "0.0667").
std::string FormatKey(double value);

}  // namespace iplan::intent
