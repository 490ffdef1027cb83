// The cell's safety parameters, one source for every reader: the
// collision-risk monitor, the trajectory optimiser (which predicts that
// monitor), the closed-loop benchmark and `iplan cell-check` all take them
// from the file their configuration names with `safety:` (the shipped
// cell: config/safety.yaml). A reader whose own file also gives one of
// these values refuses to start when it disagrees, naming both files.
// Units: s, m, m/s.
#pragma once

#include <string>

#include "iplan/safety/ssm.h"
#include "iplan/core/name_value.h"

namespace iplan::safety {

struct SafetyParams {
  /// Safety level delta_CL in (0, 1): a waypoint is safe when the bound of
  /// P(contact) is below 1 - delta_CL (METHOD 4), for the planner and the monitor.
  double delta_cl = 0.95;
  /// ISO/TS 15066 speed and separation monitoring, as the monitor applies
  /// it and the planner predicts it.
  SsmParams ssm;
  /// s; the monitor stops for a bound violation within this time (later:
  /// slows down), and compares a trajectory with standing still over it.
  double stop_horizon = 1.0;
  /// A trajectory that lowers the largest bound within stop_horizon by at
  /// least this much against the robot standing still, where standing still
  /// would reach 1 - delta_CL, takes the robot out of the person's way: the
  /// monitor does not stop it (a retreat) and the planner escapes with it
  /// when no safe plan exists; in [0, 1], 0: off.
  double bound_retreat_gain = 0.05;

  /// Empty when valid, else the reason.
  std::string Validate() const;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(delta_cl, "safe when the bound P_i < 1 - delta_cl, in (0, 1); planner and monitor"));
    a->Visit(core::MakeNameValue("iso_ts_15066", &ssm, "ISO/TS 15066 speed and separation monitoring; monitor and planner"));
    a->Visit(IPLAN_NVP(stop_horizon, "s; a bound violation within it stops, later slows down, >= 0; monitor and planner"));
    a->Visit(IPLAN_NVP(bound_retreat_gain, "a trajectory lowering the bound within stop_horizon this much against standing still is a retreat, in [0, 1], 0: off; monitor and planner"));
  }
};

/// Reads a safety file (keys as in Serialize; missing keys keep their
/// defaults; unknown keys and bad values are errors).
/// @throws core::ConfigError naming the file and key.
SafetyParams LoadSafetyParams(const std::string& path);

/// The first parameter in which a and b differ, as "key a_value vs b_value"
/// (empty when they agree).
std::string SsmDifference(const SsmParams& a, const SsmParams& b);

}  // namespace iplan::safety
