#include "trajopt_config.h"

#include "iplan/cell/safety.h"
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
  if (config.Has("safety")) {
    std::string safety_file;
    config.Read("safety", &safety_file);
    c.safety_file = config.ResolvePath(safety_file);
  }
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

planning::PlannerParams LoadPlannerParams(const TrajoptConfig& config) {
  planning::PlannerParams p = planning::LoadPlannerParams(config.planner_file, config.planner_overrides);
  if (config.safety_file.empty()) return p;
  const cell::SafetyParams safety = cell::LoadSafetyParams(config.safety_file);
  // Given in the planner's file or by an override: it must agree.
  const core::ConfigSection file =
      core::ConfigSection::Load(config.planner_file, core::ConfigSection::EmptyFile::kAllDefaults);
  auto given = [&](const std::string& key) {
    if (file.Has(key)) return true;
    for (const auto& [k, v] : config.planner_overrides)
      if (k == key || k.rfind(key + ".", 0) == 0) return true;
    return false;
  };
  if (given("delta_cl") && p.delta_cl != safety.delta_cl) {
    throw core::ConfigError(config.planner_file + ": key 'delta_cl': disagrees with " + config.safety_file + " (" +
                            core::ParamText(p.delta_cl) + " vs " + core::ParamText(safety.delta_cl) +
                            "): give it in one place");
  }
  if (const std::string d = cell::SsmDifference(p.ssm, safety.ssm); given("iso_ts_15066") && !d.empty()) {
    throw core::ConfigError(config.planner_file + ": key 'iso_ts_15066': disagrees with " + config.safety_file + " (" +
                            d + "): give it in one place");
  }
  p.delta_cl = safety.delta_cl;
  p.ssm = safety.ssm;
  if (std::string why = p.Validate(); !why.empty()) throw core::ConfigError(config.planner_file + ": " + why);
  return p;
}

std::unique_ptr<planning::Planner> MakePlanner(const TrajoptConfig& config) {
  return std::make_unique<planning::Planner>(collision::LoadRobotModel(config.robot_file),
                                             collision::LoadSceneParams(config.scene_file), LoadPlannerParams(config));
}

}  // namespace iplan::trajopt
