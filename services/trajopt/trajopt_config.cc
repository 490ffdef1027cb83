#include "trajopt_config.h"

#include "iplan/core/params.h"
#include "iplan/planning/planner_params.h"

namespace iplan::trajopt {

TrajoptConfig ReadTrajoptConfig(framework::ConfigSection& config) {
  TrajoptConfig c;
  std::string robot_file = "robots/panda.yaml", body_file = "humans/upper_body.yaml",
              scene_file = "scenes/cell.yaml";
  config.Read("robot", &robot_file);
  config.Read("human_body", &body_file);
  config.Read("scene", &scene_file);
  c.planner_overrides = config.ReadParamsFile("planner", "planner.yaml", &c.planner_file);
  config.Read("use_prediction", &c.use_prediction);
  config.Read("replan_on_prediction", &c.replan_on_prediction);
  config.Read("obstacle_timeout", &c.obstacle_timeout, framework::InRange(0.1, 60.0));
  framework::ConfigSection output = config.Section("output");
  output.Read("zero_stamp", &c.output.zero_stamp);
  output.Read("min_duration", &c.output.min_duration, framework::InRange(0.0, 60.0));
  output.Read("velocities", &c.output.velocities);
  core::ReadParams(config, &c.replanner);  // ranges: ReplannerParams::Validate
  c.robot_file = config.ResolvePath(robot_file);
  c.human_body_file = config.ResolvePath(body_file);
  c.scene_file = config.ResolvePath(scene_file);
  return c;
}

std::unique_ptr<planning::Planner> MakePlanner(const TrajoptConfig& config) {
  return std::make_unique<planning::Planner>(collision::LoadRobotModel(config.robot_file),
                                             collision::LoadSceneParams(config.scene_file),
                                             planning::LoadPlannerParams(config.planner_file, config.planner_overrides));
}

}  // namespace iplan::trajopt
