// The logic behind `iplan plan` (tools/iplan/cmd_plan.cc parses arguments).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace iplan::planning {

struct PlanCliOptions {
  std::string scene;                                   ///< scene YAML (required)
  std::string robot = "config/robots/panda.yaml";      ///< robot YAML (modified DH)
  std::string config;                                  ///< planner params YAML, empty = defaults
  std::string prediction;                              ///< prediction JSON, empty = no person
  std::string human;                                   ///< body YAML, empty = default upper body
  std::vector<double> start;                           ///< nq values (rad)
  std::vector<double> goal;                            ///< nq values (rad), or empty
  std::vector<double> goal_pose;                       ///< x,y,z,qx,qy,qz,qw (m, unit quaternion), or empty
  std::optional<int> threads;                          ///< overrides num_threads
  std::optional<std::uint64_t> seed;                   ///< overrides seed
  /// Overrides end_effector_link (the link of --goal-pose). Without it and
  /// without a config, a robot without the default Panda link uses its last
  /// link (the URDF's last in tree order, e.g. the UR5e's tool0), offset 0;
  /// likewise the default allowed_collisions (the Panda's base and first
  /// link on the table) become the robot's first two links with spheres.
  std::optional<std::string> tool_link;
  bool json = false;
};

/// Loads the files, plans and prints the result to `out`: with json, exactly
/// {"success":bool,"planning_time_s":t,"max_collision_bound":p,"delay_s":d,
///  "trajectory":{"dt":..,"positions":[[...],...]}} on one line; otherwise a
/// readable summary. Bad input (files, sizes, values) is printed to `err`.
/// @returns 0 on success, 1 when planning failed, 2 on bad input. Does not throw.
int RunPlanCommand(const PlanCliOptions& options, std::ostream& out, std::ostream& err);

}  // namespace iplan::planning
