// Reads the trajectory-optimisation settings (section trajopt of
// trajopt.yaml). Shared by the trajectory-optimisation service and
// `iplan cell-check`, which checks the task poses against the same static
// scene and planner limits.
#pragma once

#include <memory>
#include <string>

#include "core/replanner.h"
#include "iplan/framework/config.h"
#include "iplan/planning/planner.h"

namespace iplan::trajopt {

struct TrajoptConfig {
  ReplannerParams replanner;
  std::string robot_file;       ///< resolved against the configuration file
  std::string human_body_file;
  std::string scene_file;
  std::string planner_file;
  /// false: the planner ignores the person (no prediction enters the plan;
  /// only the collision-risk monitor protects), for ablations.
  bool use_prediction = true;
};

/// Reads `section` (trajopt); problems with single keys are recorded in the
/// configuration (reported by Finish()), cross-key ones are left to
/// ReplannerParams::Validate(). Keys: robot, human_body, scene, planner,
/// planning_step, frozen_waypoints, goal_tolerance, settle_speed,
/// stale_after, max_tracking_error, use_prediction.
TrajoptConfig ReadTrajoptConfig(framework::ConfigSection& section);

/// Loads the robot model, static scene and planner parameters named by
/// `config`. Throws std::exception (unreadable or invalid files).
std::unique_ptr<planning::Planner> MakePlanner(const TrajoptConfig& config);

}  // namespace iplan::trajopt
