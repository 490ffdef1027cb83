#include "risk_config.h"

#include <stdexcept>
#include <tuple>

#include "iplan/safety/safety_params.h"
#include "iplan/core/params.h"
#include "iplan/framework/service_file.h"

namespace iplan::collision_risk {

std::string RiskSettings::Validate() const {
  if (!(rate_hz >= 1 && rate_hz <= 1000)) return "rate_hz must be in [1, 1000], got " + core::ParamText(rate_hz);
  if (!(permit_validity >= 0.01 && permit_validity <= 10)) {
    return "permit_validity must be in [0.01, 10], got " + core::ParamText(permit_validity);
  }
  if (permit_validity < 2.0 / rate_hz) {
    return "permit_validity must be at least two evaluation periods (2 / rate_hz = " + core::ParamText(2.0 / rate_hz) +
           " s), got " + core::ParamText(permit_validity);
  }
  return params.Validate();
}

RiskConfig ReadRiskConfig(framework::ConfigSection& config) {
  RiskSettings settings;
  core::ReadParams(config, &settings);  // every range: RiskSettings::Validate
  RiskConfig c;
  RiskParams& p = c.params;
  p = settings.params;
  c.rate_hz = settings.rate_hz;
  c.permit_validity = settings.permit_validity;
  // The cell's safety file is the one source of delta_cl and the ISO/TS
  // 15066 parameters; values given here too must agree with it.
  if (!settings.safety.empty()) {
    c.safety_file = config.ResolvePath(settings.safety);
    try {
      const safety::SafetyParams safety = safety::LoadSafetyParams(c.safety_file);
      if (config.Has("delta_cl") && p.delta_cl != safety.delta_cl) {
        config.AddError("delta_cl", "disagrees with " + c.safety_file + " (" + core::ParamText(p.delta_cl) + " vs " +
                                        core::ParamText(safety.delta_cl) + "): give it in one place");
      }
      if (const std::string d = safety::SsmDifference(p.ssm, safety.ssm); config.Has("iso_ts_15066") && !d.empty()) {
        config.AddError("iso_ts_15066", "disagrees with " + c.safety_file + " (" + d + "): give it in one place");
      }
      for (const auto& [key, mine, cell] : {std::tuple{"stop_horizon", p.stop_horizon, safety.stop_horizon},
                                            std::tuple{"bound_retreat_gain", p.bound_retreat_gain, safety.bound_retreat_gain}}) {
        if (config.Has(key) && mine != cell) {
          config.AddError(key, std::string("disagrees with ") + c.safety_file + " (" + core::ParamText(mine) + " vs " +
                                   core::ParamText(cell) + "): give it in one place");
        }
      }
      p.delta_cl = safety.delta_cl;
      p.ssm = safety.ssm;
      p.stop_horizon = safety.stop_horizon;
      p.bound_retreat_gain = safety.bound_retreat_gain;
    } catch (const std::exception& e) {
      config.AddError("safety", e.what());
    }
  }
  c.robot_file = config.ResolvePath(settings.robot);
  c.human_body_file = config.ResolvePath(settings.human_body);
  return c;
}

RiskConfig LoadRiskConfig(const std::string& collision_risk_yaml, const std::string& robot_file) {
  framework::ServiceFile file(collision_risk_yaml);
  framework::ConfigSection section = file.Section("collision_risk");
  RiskConfig c = ReadRiskConfig(section);
  file.Finish();
  if (!robot_file.empty()) c.robot_file = robot_file;
  return c;
}

RiskMonitor MakeRiskMonitor(const RiskConfig& config) {
  return RiskMonitor(collision::LoadRobotModel(config.robot_file),
                     collision::LoadHumanBodyParams(config.human_body_file), config.params);
}

}  // namespace iplan::collision_risk
