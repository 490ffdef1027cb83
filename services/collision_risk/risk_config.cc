#include "risk_config.h"

#include <stdexcept>

namespace iplan::collision_risk {

RiskConfig ReadRiskConfig(framework::ConfigSection& config) {
  RiskConfig c;
  RiskParams& p = c.params;
  std::string robot_file = "robots/panda.yaml", body_file = "humans/upper_body.yaml";
  config.Read("robot", &robot_file);
  config.Read("human_body", &body_file);
  config.Read("rate_hz", &c.rate_hz, framework::InRange(1.0, 1000.0));
  // RiskParams' ranges are RiskParams::Validate()'s (below), not repeated here.
  config.Read("delta_cl", &p.delta_cl);
  config.Read("stop_horizon", &p.stop_horizon);
  config.Read("slow_down_fraction", &p.slow_down_fraction);
  config.Read("slow_down_margin", &p.slow_down_margin);
  config.Read("stale_after", &p.stale_after);
  config.Read("person_required", &p.person_required);
  config.Read("permit_validity", &c.permit_validity, framework::InRange(0.01, 10.0));
  config.Read("joint_limit_tolerance", &p.joint_limit_tolerance);
  framework::ConfigSection iso = config.Section("iso_ts_15066");
  SsmParams& s = p.ssm;
  iso.Read("directed", &s.directed);
  iso.Read("measure_human_speed", &s.measure_human_speed);
  iso.Read("default_human_speed", &s.default_human_speed);
  iso.Read("degrade_without_prediction", &s.degrade_without_prediction);
  iso.Read("speed_window", &s.speed_window);
  iso.Read("reaction_time", &s.reaction_time);
  iso.Read("stopping_time", &s.stopping_time);
  iso.Read("stopping_distance", &s.stopping_distance);
  iso.Read("stopping_speed", &s.stopping_speed);
  iso.Read("intrusion_distance", &s.intrusion_distance);
  iso.Read("sensing_uncertainty", &s.sensing_uncertainty);
  iso.Read("robot_uncertainty", &s.robot_uncertainty);
  if (config.Problems().empty()) {
    if (const std::string why = p.Validate(); !why.empty()) config.AddProblem(why);
  }
  c.robot_file = config.ResolvePath(robot_file);
  c.human_body_file = config.ResolvePath(body_file);
  return c;
}

RiskMonitor MakeRiskMonitor(const RiskConfig& config) {
  return RiskMonitor(collision::LoadRobotModelFromYaml(config.robot_file),
                     collision::LoadHumanBodyParams(config.human_body_file), config.params);
}

}  // namespace iplan::collision_risk
