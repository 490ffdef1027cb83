// The keys of section `intent` (config/intent.yaml), declared once: read by
// the intent service and by `iplan demo`'s cell model (which trains the
// model the service will load), listed by `iplan config defaults intent`.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "intent_estimator.h"  // beside this header
#include "iplan/core/name_value.h"
#include "iplan/intent/baseline_predictors.h"

namespace iplan::intent_service {

/// Section intent.baseline: the kinematic baselines (intent.predictor
/// constant-position / constant-velocity).
struct IntentBaselineSettings {
  std::string covariance = "model";
  double window = intent::BaselinePredictorParams{}.window;
  double sensor_noise_std = intent::BaselinePredictorParams{}.sensor_noise_std;
  double speed_std = intent::BaselinePredictorParams{}.speed_std;
  double acceleration_std = intent::BaselinePredictorParams{}.acceleration_std;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(covariance, "model (the model's covariances around the baseline's mean) or growth (the baseline's own)"));
    a->Visit(IPLAN_NVP(window, "s of history in the constant-velocity least-squares fit, > 0"));
    a->Visit(IPLAN_NVP(sensor_noise_std, "m per coordinate, noise of an observation, >= 0"));
    a->Visit(IPLAN_NVP(speed_std, "m/s, constant position: spread of the unknown speed, >= 0"));
    a->Visit(IPLAN_NVP(acceleration_std, "m/s^2, constant velocity: unmodelled acceleration, >= 0"));
  }
  /// These keys into `p` (kind, rate and horizon are the caller's).
  void ApplyTo(intent::BaselinePredictorParams* p) const {
    p->window = window;
    p->sensor_noise_std = sensor_noise_std;
    p->speed_std = speed_std;
    p->acceleration_std = acceleration_std;
  }
  /// "" when valid, else the reason (BaselinePredictorParams' ranges).
  std::string Validate() const {
    if (covariance != "model" && covariance != "growth") return "baseline.covariance must be model or growth, got '" + covariance + "'";
    intent::BaselinePredictorParams p;
    ApplyTo(&p);
    const std::string why = p.Validate();
    return why.empty() ? "" : "baseline." + why;
  }
};

struct IntentSettings {
  std::string model;                ///< model file, relative to the configuration file
  std::vector<std::string> joints;  ///< model joints, in order
  double rate_hz = 0.0;             ///< Hz, the model's frame rate
  IntentEstimatorParams estimator;  ///< its keys sit in the section itself
  std::string predictor = "model";
  IntentBaselineSettings baseline;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(model, "model file, relative to the configuration file"));
    a->Visit(IPLAN_NVP_REQUIRED(joints, "model joints, in order, not empty (the model's must match)"));
    a->Visit(IPLAN_NVP_REQUIRED(rate_hz, "Hz; model frame rate (skeletons are resampled to it; the model's must match), > 0"));
    estimator.Serialize(a);
    a->Visit(IPLAN_NVP(predictor, "what is published as the prediction: model, constant-position or constant-velocity"));
    a->Visit(IPLAN_NVP(baseline, "the kinematic baselines (iplan/intent/baseline_predictors.h)"));
  }
  /// "" when valid, else the reason with the value.
  std::string Validate() const {
    if (model.empty()) return "model must name the model file";
    if (joints.empty()) return "joints must name at least one joint";
    if (!(rate_hz > 0) || !std::isfinite(rate_hz)) return "rate_hz must be > 0, got " + std::to_string(rate_hz);
    if (std::string why = estimator.Validate(); !why.empty()) return why;
    if (predictor != "model" && predictor != "constant-position" && predictor != "constant-velocity") {
      return "predictor must be model, constant-position or constant-velocity, got '" + predictor + "'";
    }
    return baseline.Validate();
  }
};

}  // namespace iplan::intent_service
