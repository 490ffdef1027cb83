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

}  // namespace iplan::cloud
