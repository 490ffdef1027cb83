// Reads the collision-risk settings (section collision_risk of
// collision_risk.yaml). Shared by the collision-risk service and
// `iplan cell-check`, which evaluates the same monitor offline.
#pragma once

#include <string>

#include "services/collision_risk/core/risk_monitor.h"
#include "iplan/framework/config.h"

namespace iplan::collision_risk {

/// Section collision_risk, declared once: the service's own keys, then
/// RiskParams' keys inline (listed by `iplan config defaults collision-risk`).
struct RiskSettings {
  std::string robot = "robots/panda.yaml";           ///< relative to the configuration file
  std::string human_body = "humans/upper_body.yaml";  ///< relative to the configuration file
  double rate_hz = 15;
  double permit_validity = 0.2;
  std::string safety;  ///< the cell's safety file; empty: none
  RiskParams params;   ///< its keys sit in the section itself

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(robot, "robot file (URDF, overlay or DH yaml), relative to the configuration file"));
    a->Visit(IPLAN_NVP(human_body, "human body spheres file, relative to the configuration file"));
    a->Visit(IPLAN_NVP(rate_hz, "Hz, evaluations per second between predictions, in [1, 1000]"));
    a->Visit(IPLAN_NVP(permit_validity, "s; the permit published with every evaluation lapses after this, in [0.01, 10]"));
    a->Visit(IPLAN_NVP(safety, "the cell's safety file (delta_cl, iso_ts_15066, stop_horizon, bound_retreat_gain: the one source); empty: none"));
    params.Serialize(a);
  }
  std::string Validate() const;
};

struct RiskConfig {
  RiskParams params;
  double rate_hz = 15;        ///< evaluations per second between predictions
  double permit_validity = 0.2;  ///< s, validity of the permit published with every evaluation
  std::string robot_file;     ///< resolved against the configuration file
  std::string human_body_file;
  std::string safety_file;    ///< the cell's safety file (key `safety`), empty when not named
};

/// Reads `section` (collision_risk); every problem, RiskParams::Validate()'s
/// (the only ranges of RiskParams) included, is recorded in the
/// configuration (reported by Finish()). Keys: robot, human_body, rate_hz,
/// delta_cl, stop_horizon, slow_down_fraction, slow_down_margin,
/// bound_retreat_gain, stale_after, iso_ts_15066.{measure_human_speed,
/// default_human_speed, speed_window, reaction_time, stopping_time,
/// stopping_distance, intrusion_distance, sensing_uncertainty,
/// robot_uncertainty}; `safety` names the cell's safety file
/// (iplan/cell/safety.h), the one source of delta_cl, iso_ts_15066,
/// stop_horizon and bound_retreat_gain (a value given here as well that
/// disagrees is an error naming both files).
RiskConfig ReadRiskConfig(framework::ConfigSection& section);

/// Reads `collision_risk_yaml` as the collision-risk service does (section
/// collision_risk, strictly: framework::ServiceFile), for tools that build
/// the same monitor; a non-empty `robot_file` (a path as given) replaces the
/// file's robot. @throws core::ConfigError naming the file and the key.
RiskConfig LoadRiskConfig(const std::string& collision_risk_yaml, const std::string& robot_file = "");

/// Loads the robot and human models named by `config` and builds the
/// monitor. Throws std::exception (invalid params, unreadable models).
RiskMonitor MakeRiskMonitor(const RiskConfig& config);

}  // namespace iplan::collision_risk
