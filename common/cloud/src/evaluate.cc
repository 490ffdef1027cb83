#include "iplan/cloud/evaluate.h"

#include <map>
#include <stdexcept>

namespace iplan::cloud {

SceneScore ScoreScene(const std::vector<std::uint32_t>& truth, const std::vector<int>& labels,
                      const ScoreParams& params) {
  if (truth.size() != labels.size())
    throw std::invalid_argument("ScoreScene: " + std::to_string(truth.size()) + " truth labels but " +
                                std::to_string(labels.size()) + " result labels");
  SceneScore s;
  std::map<std::uint32_t, long> object_size;           // truth label -> points
  std::map<int, long> obstacle_size;                    // result label -> points
  std::map<std::pair<std::uint32_t, int>, long> joint;  // (truth, result) -> points
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::uint32_t t = truth[i];
    const int r = labels[i];
    if (t >= 1 && t <= 9) {
      ++s.table_points;
      if (r == kLabelTable) ++s.table_labelled;
    }
    if (r >= LabelOfObstacle(1)) ++obstacle_size[r];
    if (t >= 20) {
      ++object_size[t];
      if (r >= LabelOfObstacle(1)) ++joint[{t, r}];
    }
  }
  s.obstacles = static_cast<int>(obstacle_size.size());
  std::map<int, bool> matched;
  for (const auto& [t, n] : object_size) {
    if (n < params.min_object_points) continue;
    ++s.objects;
    for (const auto& [r, m] : obstacle_size) {
      const auto it = joint.find({t, r});
      const long both = it == joint.end() ? 0 : it->second;
      if (both >= params.min_object_share * n && both >= params.min_obstacle_purity * m) {
        ++s.found;
        matched[r] = true;
        break;
      }
    }
  }
  s.false_obstacles = s.obstacles - static_cast<int>(matched.size());
  return s;
}

SceneScore Add(const SceneScore& a, const SceneScore& b) {
  SceneScore s;
  s.objects = a.objects + b.objects;
  s.found = a.found + b.found;
  s.obstacles = a.obstacles + b.obstacles;
  s.false_obstacles = a.false_obstacles + b.false_obstacles;
  s.table_points = a.table_points + b.table_points;
  s.table_labelled = a.table_labelled + b.table_labelled;
  return s;
}

namespace {

// Which of two totals is better: more found minus false, then fewer false.
bool Better(const SceneScore& a, const SceneScore& b) {
  const int ma = a.found - a.false_obstacles, mb = b.found - b.false_obstacles;
  return ma != mb ? ma > mb : a.false_obstacles < b.false_obstacles;
}

// The best setting on the scenes not excluded, and its total there.
int Choose(const std::vector<std::vector<SceneScore>>& scores, const std::vector<char>& excluded,
           SceneScore* total) {
  int best = -1;
  SceneScore best_total;
  for (std::size_t k = 0; k < scores[0].size(); ++k) {
    SceneScore t;
    for (std::size_t s = 0; s < scores.size(); ++s)
      if (!excluded[s]) t = Add(t, scores[s][k]);
    if (best < 0 || Better(t, best_total)) {
      best = static_cast<int>(k);
      best_total = t;
    }
  }
  if (total) *total = best_total;
  return best;
}

}  // namespace

CrossValidation CrossValidate(const std::vector<std::vector<SceneScore>>& scores,
                              const std::vector<std::vector<int>>& folds) {
  if (scores.empty() || scores[0].empty()) throw std::invalid_argument("CrossValidate: no scenes or no settings");
  for (const auto& row : scores)
    if (row.size() != scores[0].size())
      throw std::invalid_argument("CrossValidate: scenes scored on different numbers of settings");
  std::vector<int> seen(scores.size(), 0);
  for (const auto& fold : folds) {
    if (fold.empty()) throw std::invalid_argument("CrossValidate: an empty fold");
    for (const int s : fold) {
      if (s < 0 || s >= static_cast<int>(scores.size()))
        throw std::invalid_argument("CrossValidate: scene " + std::to_string(s) + " out of range");
      ++seen[s];
    }
  }
  for (std::size_t s = 0; s < seen.size(); ++s)
    if (seen[s] != 1)
      throw std::invalid_argument("CrossValidate: scene " + std::to_string(s) + " is in " + std::to_string(seen[s]) +
                                  " folds, not 1");
  CrossValidation cv;
  for (const auto& scenes : folds) {
    CrossValidation::Fold f;
    f.scenes = scenes;
    std::vector<char> excluded(scores.size(), 0);
    for (const int s : scenes) excluded[s] = 1;
    f.chosen = Choose(scores, excluded, nullptr);
    for (const int s : scenes) f.score = Add(f.score, scores[s][f.chosen]);
    cv.held_out = Add(cv.held_out, f.score);
    cv.folds.push_back(f);
  }
  cv.chosen_all = Choose(scores, std::vector<char>(scores.size(), 0), &cv.all);
  return cv;
}

}  // namespace iplan::cloud
