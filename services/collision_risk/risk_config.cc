#include "risk_config.h"

#include <stdexcept>

#include "iplan/core/params.h"

namespace iplan::collision_risk {

RiskConfig ReadRiskConfig(framework::ConfigSection& config) {
  RiskConfig c;
  RiskParams& p = c.params;
  std::string robot_file = "robots/panda.yaml", body_file = "humans/upper_body.yaml";
  config.Read("robot", &robot_file);
  config.Read("human_body", &body_file);
  config.Read("rate_hz", &c.rate_hz, framework::InRange(1.0, 1000.0));
  config.Read("permit_validity", &c.permit_validity, framework::InRange(0.01, 10.0));
  core::ReadParams(config, &p);  // every range: RiskParams::Validate
  c.robot_file = config.ResolvePath(robot_file);
  c.human_body_file = config.ResolvePath(body_file);
  return c;
}

RiskMonitor MakeRiskMonitor(const RiskConfig& config) {
  return RiskMonitor(collision::LoadRobotModel(config.robot_file),
                     collision::LoadHumanBodyParams(config.human_body_file), config.params);
}

}  // namespace iplan::collision_risk
