// Training of the intent model, METHOD.md sections 2-3: the training tracks
// (model joints at the model rate), then the action classifier
// (intent_classifier_training.cc) and the per-action forecasters
// (intent_forecaster_training.cc). Prediction is in intent_prediction.cc,
// the config checks in intent_config.cc.
#include "iplan/intent/intent_model.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <stdexcept>

#include "intent_training.h"

namespace iplan::intent {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

std::vector<Track> MakeTracks(const SkeletonDataset& data, const IntentModelConfig& config,
                              double max_gap) {
  for (const std::string& j : config.joints.joints) {
    if (std::find(data.joint_names.begin(), data.joint_names.end(), j) == data.joint_names.end()) {
      std::string list;
      for (const std::string& a : data.joint_names) list += (list.empty() ? "" : ",") + a;
      throw std::invalid_argument("model joint '" + j + "' is not in the data (data joints: " +
                                  list + ")");
    }
  }
  const std::vector<int> idx = JointIndices(data.joint_names, config.joints.joints);
  std::vector<Track> tracks;
  for (const SkeletonSequence& s : data.sequences) {
    for (Track& t : ResampleSequence(s, idx, config.rate, max_gap)) tracks.push_back(std::move(t));
  }
  return tracks;
}

IntentModel TrainIntentModel(const SkeletonDataset& data, const IntentModelConfig& config,
                             const TrainParams& params, TrainReport* report) {
  std::string error = config.Validate();
  if (!error.empty()) throw std::invalid_argument("IntentModelConfig: " + error);
  error = params.Validate();
  if (!error.empty()) throw std::invalid_argument("TrainParams: " + error);
  const FeatureLayout layout(config.joints, config.features);
  const std::vector<Track> tracks = MakeTracks(data, config, params.max_gap);

  IntentModel model;
  model.config = config;
  std::set<std::string> action_set;
  for (const Track& t : tracks) {
    if (t.frame_actions.empty()) action_set.insert(t.action);
    action_set.insert(t.frame_actions.begin(), t.frame_actions.end());
  }
  model.actions.assign(action_set.begin(), action_set.end());
  if (model.actions.size() < 2) {
    throw std::invalid_argument("TrainIntentModel: need at least two actions, got " +
                                std::to_string(model.actions.size()));
  }
  detail::TrainingGroups groups{tracks, {}, {}, 0, 0};
  for (size_t c = 0; c < model.actions.size(); ++c) groups.action_id[model.actions[c]] = static_cast<int>(c);
  for (const Track& t : tracks) groups.subject_id.emplace(t.subject, static_cast<int>(groups.subject_id.size()));
  groups.num_actions = static_cast<int>(model.actions.size());
  groups.num_subjects = static_cast<int>(groups.subject_id.size());
  TrainReport rep;

  auto t0 = std::chrono::steady_clock::now();
  detail::TrainClassifier(groups, layout, config, params, &model.classifier, &rep);
  rep.seconds_classifier = Seconds(t0);

  t0 = std::chrono::steady_clock::now();
  detail::TrainForecasters(groups, layout, config, params, &model, &rep);
  rep.seconds_forecaster = Seconds(t0);
  if (report != nullptr) *report = rep;
  return model;
}

}  // namespace iplan::intent
