#include "trajopt_config.h"

#include "iplan/planning/planner_params.h"

namespace iplan::trajopt {

TrajoptConfig ReadTrajoptConfig(framework::ConfigSection& config) {
  TrajoptConfig c;
  std::string robot_file = "robots/panda.yaml", body_file = "humans/upper_body.yaml",
              scene_file = "scenes/cell.yaml", planner_file = "planner.yaml";
  config.Read("robot", &robot_file);
  config.Read("human_body", &body_file);
  config.Read("scene", &scene_file);
  config.Read("planner", &planner_file);
  config.Read("use_prediction", &c.use_prediction);
  ReplannerParams& p = c.replanner;
  config.Read("planning_step", &p.planning_step, framework::InRange(0.01, 2.0));
  config.Read("frozen_waypoints", &p.frozen_waypoints, framework::InRange(2, 50));
  config.Read("goal_tolerance", &p.goal_tolerance, framework::Positive<double>());
  config.Read("settle_speed", &p.settle_speed, framework::Positive<double>());
  config.Read("stale_after", &p.stale_after, framework::Positive<double>());
  config.Read("max_tracking_error", &p.max_tracking_error, framework::Positive<double>());
  config.Read("joint_limit_tolerance", &p.joint_limit_tolerance, framework::NonNegative<double>());
  config.Read("joint_velocity_factor", &p.joint_velocity_factor, framework::InRange(1.0, 10.0));
  c.robot_file = config.ResolvePath(robot_file);
  c.human_body_file = config.ResolvePath(body_file);
  c.scene_file = config.ResolvePath(scene_file);
  c.planner_file = config.ResolvePath(planner_file);
  return c;
}

std::unique_ptr<planning::Planner> MakePlanner(const TrajoptConfig& config) {
  return std::make_unique<planning::Planner>(collision::LoadRobotModelFromYaml(config.robot_file),
                                             collision::LoadSceneParams(config.scene_file),
                                             planning::LoadPlannerParams(config.planner_file));
}

}  // namespace iplan::trajopt
