// Scores a segmentation against per-point ground truth (mOSD-style labels:
// 0 invalid, 1-9 table, >= 20 objects), with the metric of issue 18:
//   - every ground-truth label value >= 20 held by at least
//     `min_object_points` points is one object;
//   - an object is found when one reported obstacle holds >= 50 % of its
//     points and >= 80 % of that obstacle's points are the object's;
//   - a false obstacle is a reported obstacle that found no object;
//   - the table rate is the share of table points (1-9) labelled table.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "iplan/cloud/pipeline.h"

namespace iplan::cloud {

struct SceneScore {
  int objects = 0;          ///< ground-truth objects
  int found = 0;            ///< of them, found
  int obstacles = 0;        ///< reported obstacles
  int false_obstacles = 0;  ///< reported obstacles that found no object
  long table_points = 0;    ///< ground-truth table points
  long table_labelled = 0;  ///< of them, labelled table
};

struct ScoreParams {
  int min_object_points = 500;
  double min_object_share = 0.5;    ///< of the object's points in the obstacle
  double min_obstacle_purity = 0.8;  ///< of the obstacle's points from the object
};

/// Scores `labels` (one per point, as Result::labels) against `truth` (the
/// cloud's label field). Throws std::invalid_argument on a size mismatch.
SceneScore ScoreScene(const std::vector<std::uint32_t>& truth, const std::vector<int>& labels,
                      const ScoreParams& params = {});

/// Sum of scenes (for totals).
SceneScore Add(const SceneScore& a, const SceneScore& b);

}  // namespace iplan::cloud
