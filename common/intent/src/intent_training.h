// The pieces of TrainIntentModel and PredictIntent (METHOD.md sections 2-3),
// internal to iplan::intent:
//
//   TrainingGroups       action, subject and forecaster-fold ids of the
//                        training tracks                       (intent_model.cc)
//   TrainClassifier      METHOD 2: DTW kernel, IVM, cross-validation of
//                        (sigma, lambda) and of the belief filter
//                                                              (intent_classifier_training.cc)
//   TrainForecasters     METHOD 3: per-action SPGP forecasters, kinematic
//                        baseline, residual weight, covariance calibration
//                                                              (intent_forecaster_training.cc)
//   PredictResidual,     the forecast of one SPGP and the activity factor,
//   ActivityFactor       shared by training and prediction      (intent_prediction.cc)
//
// TrainIntentModel (intent_model.cc) orchestrates them; the config checks
// are in intent_config.cc. Units: m, s; positions in the data frame W.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/intent/features.h"
#include "iplan/intent/intent_model.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::intent::detail {

// The training tracks with their ids: actions in model order, subjects in
// order of first appearance (the classifier's cross-validation folds).
struct TrainingGroups {
  const std::vector<Track>& tracks;
  std::map<std::string, int> action_id, subject_id;
  int num_actions = 0;   // C
  int num_subjects = 0;  // subject_id.size()
};

// Trains the action classifier of METHOD 2 on the windows ending at the
// prefix fractions of every track; fills `classifier` (sigma, IVM, import
// windows, belief filter) and the classifier part of `rep`.
void TrainClassifier(const TrainingGroups& groups, const FeatureLayout& layout,
                     const IntentModelConfig& config, const TrainParams& params,
                     ActionClassifier* classifier, TrainReport* rep);

// Trains the per-action forecasters of METHOD 3 and chooses their
// ForecastSettings (see there); fills model->forecast, model->forecasters
// (model->actions names the actions in messages) and the forecaster part of
// `rep`. Throws std::invalid_argument for an action with fewer than two
// forecaster windows.
void TrainForecasters(const TrainingGroups& groups, const FeatureLayout& layout,
                      const IntentModelConfig& config, const TrainParams& params,
                      IntentModel* model, TrainReport* rep);

// rho_j^2 of ForecastSettings for window speeds `u` (J).
double ActivityFactor(const ForecastSettings& f, const Eigen::VectorXd& u, int j);

// Predicted residual (P, m) and its variance (P, m^2, without sensor noise)
// for the unstandardised input `x`.
void PredictResidual(const ActionForecaster& fc, const Eigen::VectorXd& x, Eigen::VectorXd* mean,
                     Eigen::VectorXd* var);

}  // namespace iplan::intent::detail
