// The keys of section `supervisor` (config/supervisor.yaml), declared once:
// read by the supervisor service and by the offline cell (cell_sim), listed
// by `iplan config defaults supervisor`. Times in s.
#pragma once

#include <string>
#include <vector>

#include "services/supervisor/core/human_graph.h"
#include "services/supervisor/core/task_planner.h"
#include "iplan/core/name_value.h"

namespace iplan::supervisor {

struct SupervisorSettings {
  std::string task_graph = "tasks/table_top.yaml";
  std::string trajopt_config = "trajopt.yaml";
  std::string robot;
  std::string q_table = "state/q_table.bin";
  std::string mode = "learning";
  QLearningParams learning;  ///< its keys sit in the section itself
  ActionTrackerParams tracker;  ///< so do these
  std::vector<std::string> watch = {"human_skeleton", "human_prediction", "joint_states", "robot_trajectory",
                                    "collision_risk"};
  double pause_between_tasks = 0.5;
  double resume_delay = 0.5;
  int max_episodes = 0;
  double permit_period = 0.05;
  double permit_validity = 0.2;
  double command_resend_period = 1.0;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(task_graph, "task graph file, relative to the configuration file"));
    a->Visit(IPLAN_NVP(trajopt_config, "the trajectory optimiser's file: its robot, scene and planner solve the task graph's poses"));
    a->Visit(IPLAN_NVP(robot, "robot file instead of trajopt_config's (relative to this file; iplan demo --robot); \"\" = its"));
    a->Visit(IPLAN_NVP(q_table, "Q-table file, relative to the configuration file; empty = not kept"));
    a->Visit(IPLAN_NVP(mode, "learning or deployment (greedy, no updates)"));
    learning.Serialize(a);
    tracker.Serialize(a);
    a->Visit(IPLAN_NVP(watch, "topics of the deadline / liveliness monitor; not empty in deployment"));
    a->Visit(IPLAN_NVP(pause_between_tasks, "s; >= 0"));
    a->Visit(IPLAN_NVP(resume_delay, "s; causes of a stop stay clear this long before resuming, in [0, 10]"));
    a->Visit(IPLAN_NVP(max_episodes, "stop after this many episodes, >= 0 (0 = no limit)"));
    a->Visit(IPLAN_NVP(permit_period, "s; safety permit publishing period, in [0.005, 1]"));
    a->Visit(IPLAN_NVP(permit_validity, "s; validity of one permit, in [0.01, 10] and >= 2 permit_period"));
    a->Visit(IPLAN_NVP(command_resend_period, "s; an unanswered task command is resent, in [0.1, 60]"));
  }
  /// "" when valid, else the reason naming the key (all ranges, including
  /// QLearningParams::Validate()'s and
  /// ActionTrackerParams::Validate()'s).
  std::string Validate() const;
};

}  // namespace iplan::supervisor
