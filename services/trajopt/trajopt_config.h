// Reads the trajectory-optimisation settings (section trajopt of
// trajopt.yaml). Shared by the trajectory-optimisation service and
// `iplan cell-check`, which checks the task poses against the same static
// scene and planner limits.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "iplan/adapters/adapters.h"
#include "services/trajopt/core/replanner.h"
#include "iplan/core/name_value.h"
#include "iplan/framework/config.h"
#include "iplan/planning/planner.h"

namespace iplan::trajopt {

/// The keys of section `trajopt` (config/trajopt.yaml) besides
/// ReplannerParams' (which sit in the same section), declared once; the
/// file names as written (ReadTrajoptConfig resolves them into
/// TrajoptConfig). `iplan config defaults trajopt` lists both.
struct TrajoptSettings {
  std::string robot = "robots/panda.yaml";
  std::string human_body = "humans/upper_body.yaml";
  std::string scene = "scenes/cell.yaml";
  std::string planner = "planner.yaml";
  std::optional<std::string> safety;
  bool use_prediction = true;
  bool replan_on_prediction = true;
  double obstacle_timeout = 2.0;
  services::TrajectoryOutput output;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(robot, "robot model file (docs/robots.md), relative to the configuration file"));
    a->Visit(IPLAN_NVP(human_body, "human body model file, relative to the configuration file"));
    a->Visit(IPLAN_NVP(scene, "static scene file, relative to the configuration file"));
    a->Visit(IPLAN_NVP(planner, "planner parameter file (PlannerParams), relative to the configuration file"));
    a->Visit(IPLAN_NVP(safety, "the cell's safety file (delta_cl, iso_ts_15066 for the planner); absent: the planner file's"));
    a->Visit(IPLAN_NVP(use_prediction, "false: plans ignore the person (only the monitor protects), for ablations"));
    a->Visit(IPLAN_NVP(replan_on_prediction, "a cycle starts when a prediction arrives; false: only on the planning_step tick"));
    a->Visit(IPLAN_NVP(obstacle_timeout, "s a box of /iplan/obstacles stays in the plans' scene after it was last seen, in [0.1, 60]"));
    a->Visit(IPLAN_NVP(output, "how trajectories are stamped and shaped (docs/topics.md)"));
  }
  /// "" when valid, else the reason.
  std::string Validate() const {
    if (!(obstacle_timeout >= 0.1 && obstacle_timeout <= 60.0)) return "obstacle_timeout must be in [0.1, 60] s";
    return output.Validate();
  }
};

struct TrajoptConfig {
  ReplannerParams replanner;
  std::string robot_file;       ///< resolved against the configuration file
  std::string human_body_file;
  std::string scene_file;
  std::string planner_file;
  /// --set trajopt.planner.KEY=VALUE overrides, for LoadPlannerParams.
  core::Overrides planner_overrides;
  /// The cell's safety file (key `safety`, iplan/cell/safety.h), empty when
  /// not named: the planner's delta_cl and iso_ts_15066 come from it.
  std::string safety_file;
  /// false: the planner ignores the person (no prediction enters the plan;
  /// only the collision-risk monitor protects), for ablations.
  bool use_prediction = true;
  /// true: a cycle starts when a prediction arrives (and on the planning
  /// step's tick when none does); false: only on the tick.
  bool replan_on_prediction = true;
  /// s a box of /iplan/obstacles stays in the plan's scene after it was
  /// last seen (core/obstacle_set.h).
  double obstacle_timeout = 2.0;
  /// How trajectories are stamped and shaped (section trajopt.output: keys
  /// zero_stamp, min_duration (s, >= 0), velocities).
  services::TrajectoryOutput output;
};

/// Reads `section` (trajopt); every problem, ReplannerParams::Validate()'s
/// included, is recorded in the configuration (reported by Finish()). Keys:
/// robot, human_body, scene, planner (file names, relative to the
/// configuration file), use_prediction, replan_on_prediction, obstacle_timeout and ReplannerParams::Serialize's.
TrajoptConfig ReadTrajoptConfig(framework::ConfigSection& section);

/// Reads `trajopt_yaml` as the trajectory optimiser does (section trajopt,
/// strictly: framework::ServiceFile), for tools and services that plan with
/// its robot, scene and planner; a non-empty `robot_file` (a path as given,
/// already resolved) replaces the file's robot. @throws core::ConfigError
/// naming the file and the key.
TrajoptConfig LoadTrajoptConfig(const std::string& trajopt_yaml, const std::string& robot_file = "");

/// The planner parameters named by `config`: the planner file with its
/// overrides, delta_cl and iso_ts_15066 from the safety file. A planner
/// file (or override) that gives either and disagrees with the safety file
/// is refused. @throws core::ConfigError naming both files.
planning::PlannerParams LoadPlannerParams(const TrajoptConfig& config);

/// Loads the robot model, static scene and planner parameters named by
/// `config`. Throws std::exception (unreadable or invalid files).
std::unique_ptr<planning::Planner> MakePlanner(const TrajoptConfig& config);

}  // namespace iplan::trajopt
