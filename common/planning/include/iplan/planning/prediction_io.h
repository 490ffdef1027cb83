// Human prediction files for the planner (format in docs/planning.md):
//
//   {"dt": 0.1,                       // s between prediction steps, > 0
//    "start_time": 0.0,               // optional: time of step 0 minus the time
//                                     // of the trajectory's first waypoint (s)
//    "joints": ["head", "neck", ...], // skeleton joint names (all of the body's)
//    "actions": [
//      {"name": "reach_bin",          // optional
//       "probability": 0.6,           // p(c) >= 0, sum <= 1 (+1e-6)
//       "steps": [                    // same count for every action
//         {"mean": [[x, y, z], ...],  // per joint, m, world frame W
//          "cov":  [[9 numbers], ...]}// per joint, row-major 3x3, m^2, SPD
//       ]}]}
//
// Converted to collision::HumanPrediction through a HumanBodyModel: each
// sphere's centre Gaussian follows from its two joints' Gaussians.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "iplan/collision/human_model.h"
#include "iplan/collision/trajectory_bound.h"

namespace iplan::planning {

struct PredictionFile {
  double dt = 0.1;          ///< s
  double start_time = 0.0;  ///< s
  std::vector<std::string> action_names;
  /// Sphere prediction, summaries up to date. Never null after loading.
  std::unique_ptr<collision::HumanPrediction> prediction;
};

/// Parses the JSON text above. `source` names the input in error messages.
/// @throws std::runtime_error naming the source, the key/index and the value
///         (unknown keys, missing joints, wrong sizes, non-SPD covariance,
///         probabilities outside [0, 1] or summing above 1).
/// Thread-safe; allocates.
PredictionFile ParsePredictionJson(const std::string& text, const collision::HumanBodyModel& body,
                                   const std::string& source = "prediction");
/// Reads and parses a file. @throws std::runtime_error as above.
PredictionFile LoadPredictionFile(const std::string& path, const collision::HumanBodyModel& body);

}  // namespace iplan::planning
