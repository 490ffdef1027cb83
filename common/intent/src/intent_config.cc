// The checks of the intent model's configuration and training parameters
// (METHOD.md sections 2-3; the fields are documented in intent_model.h).
#include <cmath>
#include <string>

#include "iplan/intent/intent_model.h"

namespace iplan::intent {

std::string IntentModelConfig::Validate() const {
  const std::string j = joints.Validate();
  if (!j.empty()) return "joints: " + j;
  if (!(rate > 0.0) || !std::isfinite(rate)) return "rate " + std::to_string(rate) + " must be > 0";
  if (window < 2) return "window " + std::to_string(window) + " must be >= 2";
  if (horizon < 1) return "horizon " + std::to_string(horizon) + " must be >= 1";
  if (velocity_frames < 1) return "velocity_frames " + std::to_string(velocity_frames) + " must be >= 1";
  if (history_samples < 0 || history_samples >= window) {
    return "history_samples " + std::to_string(history_samples) + " must be in [0, window - 1 = " +
           std::to_string(window - 1) + "]";
  }
  if (dtw_band < 0) return "dtw_band " + std::to_string(dtw_band) + " must be >= 0";
  if (!(sensor_noise_std >= 0.0)) return "sensor_noise_std must be >= 0";
  if (!(features.torso_motion_weight >= 0.0)) return "features.torso_motion_weight must be >= 0";
  return "";
}

std::string TrainParams::Validate() const {
  if (!(max_gap > 0.0)) return "max_gap " + std::to_string(max_gap) + " must be > 0";
  if (prefix_fractions.empty()) return "prefix_fractions is empty";
  for (double f : prefix_fractions) {
    if (!(f > 0.0 && f <= 1.0)) return "prefix fraction " + std::to_string(f) + " outside (0, 1]";
  }
  if (sigma_factors.empty() || lambdas.empty()) return "sigma_factors and lambdas must not be empty";
  for (double s : sigma_factors) if (!(s > 0.0)) return "sigma factor " + std::to_string(s) + " must be > 0";
  for (double l : lambdas) if (!(l > 0.0)) return "lambda " + std::to_string(l) + " must be > 0";
  if (mirror_augmentation.empty()) return "mirror_augmentation is empty";
  if (belief_time_constants.empty()) return "belief_time_constants is empty";
  if (belief_motion_weighting.empty()) return "belief_motion_weighting is empty";
  for (double t : belief_time_constants) {
    if (!(t >= 0.0)) return "belief time constant " + std::to_string(t) + " must be >= 0";
  }
  if (!(belief_min_probability > 0.0 && belief_min_probability < 1.0)) {
    return "belief_min_probability " + std::to_string(belief_min_probability) + " must be in (0, 1)";
  }
  const std::string ivm_error = ivm.Validate();
  if (!ivm_error.empty() && ivm_error.find("lambda") == std::string::npos) return "ivm: " + ivm_error;
  if (pseudo_inputs < 1) return "pseudo_inputs " + std::to_string(pseudo_inputs) + " must be >= 1";
  if (threads < 0 || threads > 256) return "threads " + std::to_string(threads) + " must be in [0, 256]";
  if (forecast_stride < 1) return "forecast_stride must be >= 1";
  if (max_forecast_windows < 2) return "max_forecast_windows must be >= 2";
  if (gp_iterations < 0) return "gp_iterations must be >= 0";
  if (baseline_smoothing_frames.empty() || baseline_damping_time_constants.empty() ||
      residual_weights.empty()) {
    return "baseline_smoothing_frames, baseline_damping_time_constants and residual_weights "
           "must not be empty";
  }
  for (int L : baseline_smoothing_frames) {
    if (L < 1) return "baseline smoothing frames " + std::to_string(L) + " must be >= 1";
  }
  for (double tau : baseline_damping_time_constants) {
    if (!(tau >= 0.0)) return "baseline damping time constant " + std::to_string(tau) + " must be >= 0";
  }
  for (double w : residual_weights) {
    if (!(w >= 0.0 && w <= 1.0)) return "residual weight " + std::to_string(w) + " outside [0, 1]";
  }
  if (forecast_cv_folds < 2) return "forecast_cv_folds " + std::to_string(forecast_cv_folds) + " must be >= 2";
  if (motion_offsets.empty()) return "motion_offsets must not be empty";
  for (double m0 : motion_offsets) {
    if (!(m0 > 0.0)) return "motion offset " + std::to_string(m0) + " must be > 0 m/s";
  }
  return "";
}

std::string ForecastSettings::Validate(int horizon, int num_joints) const {
  if (const std::string why = baseline.Validate(); !why.empty()) return "baseline: " + why;
  if (!(residual_weight >= 0.0 && residual_weight <= 1.0)) {
    return "residual_weight " + std::to_string(residual_weight) + " outside [0, 1]";
  }
  if (variance_scale.size() != 0) {
    if (variance_scale.size() != static_cast<Eigen::Index>(horizon) * num_joints) {
      return "variance_scale has " + std::to_string(variance_scale.size()) + " entries, expected " +
             std::to_string(horizon * num_joints) + " (horizon x joints)";
    }
    if (!variance_scale.allFinite() || !(variance_scale.array() > 0.0).all()) {
      return "variance_scale entries must be finite and > 0";
    }
  }
  if (!(motion_offset > 0.0)) return "motion_offset " + std::to_string(motion_offset) + " must be > 0 m/s";
  if (std::isfinite(motion_offset) || reference_speed.size() != 0) {
    if (reference_speed.size() != num_joints) {
      return "reference_speed has " + std::to_string(reference_speed.size()) + " entries, expected " +
             std::to_string(num_joints) + " (joints)";
    }
    if (!reference_speed.allFinite() || (reference_speed.array() < 0.0).any()) {
      return "reference_speed entries must be finite and >= 0";
    }
  }
  return "";
}

}  // namespace iplan::intent
