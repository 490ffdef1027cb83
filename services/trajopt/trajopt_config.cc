#include "trajopt_config.h"

#include "iplan/safety/safety_params.h"
#include "iplan/core/params.h"
#include "iplan/framework/service_file.h"
#include "iplan/planning/planner_params.h"

namespace iplan::trajopt {

TrajoptConfig ReadTrajoptConfig(framework::ConfigSection& config) {
  TrajoptConfig c;
  // The planner file's own overrides (--set trajopt.planner.KEY=VALUE), for
  // LoadPlannerParams; the key itself is declared in TrajoptSettings.
  c.planner_overrides = config.ReadParamsFile("planner", "planner.yaml", &c.planner_file);
  TrajoptSettings s;
  core::ReadParams(config, &s);            // ranges: TrajoptSettings::Validate
  core::ReadParams(config, &c.replanner);  // ranges: ReplannerParams::Validate
  c.use_prediction = s.use_prediction;
  c.replan_on_prediction = s.replan_on_prediction;
  c.obstacle_timeout = s.obstacle_timeout;
  c.output = s.output;
  if (s.safety) {
    c.safety_file = config.ResolvePath(*s.safety);
    // Escaping predicts the monitor's bound retreat: its horizon and gain.
    try {
      const safety::SafetyParams safety = safety::LoadSafetyParams(c.safety_file);
      c.replanner.escape.horizon = safety.stop_horizon;
      c.replanner.escape.gain = safety.bound_retreat_gain;
    } catch (const std::exception& e) {
      config.AddError("safety", e.what());
    }
  }
  c.robot_file = config.ResolvePath(s.robot);
  c.human_body_file = config.ResolvePath(s.human_body);
  c.scene_file = config.ResolvePath(s.scene);
  return c;
}

TrajoptConfig LoadTrajoptConfig(const std::string& trajopt_yaml, const std::string& robot_file) {
  framework::ServiceFile file(trajopt_yaml);
  framework::ConfigSection section = file.Section("trajopt");
  TrajoptConfig c = ReadTrajoptConfig(section);
  file.Finish();
  if (!robot_file.empty()) c.robot_file = robot_file;
  return c;
}

planning::PlannerParams LoadPlannerParams(const TrajoptConfig& config) {
  planning::PlannerParams p = planning::LoadPlannerParams(config.planner_file, config.planner_overrides);
  if (config.safety_file.empty()) return p;
  const safety::SafetyParams safety = safety::LoadSafetyParams(config.safety_file);
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
  if (const std::string d = safety::SsmDifference(p.ssm, safety.ssm); given("iso_ts_15066") && !d.empty()) {
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
