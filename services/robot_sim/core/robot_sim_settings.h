// The keys of section `robot_sim` (config/robot_sim.yaml), declared once:
// read by the robot simulator service and by the offline cell (cell_sim),
// listed by `iplan config defaults robot-sim`.
#pragma once

#include <string>
#include <vector>

#include "services/robot_sim/core/robot_simulator.h"
#include "iplan/core/name_value.h"
#include "iplan/safety/permit_gate.h"

namespace iplan::robot_sim {

struct RobotSimSettings {
  std::string robot = "robots/panda.yaml";
  std::string human_body = "humans/upper_body.yaml";
  std::vector<double> initial_positions = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};
  double control_rate_hz = 100;
  double publish_rate_hz = 50;
  SimulatorParams simulator;  ///< its keys sit in the section itself
  safety::PermitGateParams permits{{"iplan-supervisor", "iplan-collision_risk"}};

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(robot, "robot model file, relative to the configuration file"));
    a->Visit(IPLAN_NVP(human_body, "human body model file, relative to the configuration file"));
    a->Visit(IPLAN_NVP(initial_positions, "rad; the arm's start, model joint order"));
    a->Visit(IPLAN_NVP(control_rate_hz, "Hz; simulation steps per second, in [10, 2000]"));
    a->Visit(IPLAN_NVP(publish_rate_hz, "Hz; joint states per second, in [1, 1000]"));
    simulator.Serialize(a);
    a->Visit(IPLAN_NVP(permits, "the permit gate"));
  }
  /// "" when valid, else the reason (SimulatorParams' and PermitGateParams'
  /// ranges included).
  std::string Validate() const {
    if (!(control_rate_hz >= 10 && control_rate_hz <= 2000)) return "control_rate_hz must be in [10, 2000]";
    if (!(publish_rate_hz >= 1 && publish_rate_hz <= 1000)) return "publish_rate_hz must be in [1, 1000]";
    if (std::string why = simulator.Validate(); !why.empty()) return why;
    return permits.Validate();
  }
};

}  // namespace iplan::robot_sim
