#include "risk_config.h"

#include <stdexcept>

#include "iplan/cell/safety.h"
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
  // The cell's safety file is the one source of delta_cl and the ISO/TS
  // 15066 parameters; values given here too must agree with it.
  if (config.Has("safety")) {
    std::string safety_file;
    config.Read("safety", &safety_file);
    c.safety_file = config.ResolvePath(safety_file);
    try {
      const cell::SafetyParams safety = cell::LoadSafetyParams(c.safety_file);
      if (config.Has("delta_cl") && p.delta_cl != safety.delta_cl) {
        config.AddError("delta_cl", "disagrees with " + c.safety_file + " (" + core::ParamText(p.delta_cl) + " vs " +
                                        core::ParamText(safety.delta_cl) + "): give it in one place");
      }
      if (const std::string d = cell::SsmDifference(p.ssm, safety.ssm); config.Has("iso_ts_15066") && !d.empty()) {
        config.AddError("iso_ts_15066", "disagrees with " + c.safety_file + " (" + d + "): give it in one place");
      }
      p.delta_cl = safety.delta_cl;
      p.ssm = safety.ssm;
    } catch (const std::exception& e) {
      config.AddError("safety", e.what());
    }
  }
  c.robot_file = config.ResolvePath(robot_file);
  c.human_body_file = config.ResolvePath(body_file);
  return c;
}

RiskMonitor MakeRiskMonitor(const RiskConfig& config) {
  return RiskMonitor(collision::LoadRobotModel(config.robot_file),
                     collision::LoadHumanBodyParams(config.human_body_file), config.params);
}

}  // namespace iplan::collision_risk
