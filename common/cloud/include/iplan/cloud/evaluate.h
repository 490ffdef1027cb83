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

/// Cross-validated choice among parameter settings: in each fold the
/// setting with the best score on the other scenes (most objects found
/// minus false obstacles; ties: fewer false obstacles, then the earlier
/// setting) is scored on the fold's scenes, which had no say in it.
struct CrossValidation {
  struct Fold {
    std::vector<int> scenes;  ///< held out
    int chosen = -1;          ///< setting chosen on the other scenes
    SceneScore score;         ///< its score on the held-out scenes
  };
  std::vector<Fold> folds;
  SceneScore held_out;  ///< the folds' held-out scores, summed: the cross-validated figure
  int chosen_all = -1;  ///< the setting the same rule chooses on all scenes
  SceneScore all;       ///< its score on all scenes (tuned on them: optimistic)
};

/// scores[scene][setting] (every scene the same number of settings, at
/// least one); folds: lists of scene indices, every scene in exactly one,
/// none empty. Throws std::invalid_argument otherwise.
CrossValidation CrossValidate(const std::vector<std::vector<SceneScore>>& scores,
                              const std::vector<std::vector<int>>& folds);

}  // namespace iplan::cloud
