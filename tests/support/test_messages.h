// Messages the multi-process tests build again and again.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/msg/types.h"

namespace iplan::testing {

/// The Panda's joints, in the order the cell's trajectories and joint states
/// carry them (config/robots/panda.yaml).
inline const std::vector<std::string> kPandaJoints = {"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                                      "panda_joint5", "panda_joint6", "panda_joint7"};
/// The Panda's ready pose (rad), where the simulated robot starts.
inline const std::vector<double> kPandaReady = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};
/// The upper-body skeleton's joints (collision::HumanBodyParams::DefaultUpperBody).
inline const std::vector<std::string> kUpperBodyJoints = {"head",   "neck",       "torso",   "shoulder_l", "elbow_l",
                                                          "hand_l", "shoulder_r", "elbow_r", "hand_r"};

/// A skeleton in the cell frame: joint j named names[j] at positions[j]
/// (m, world), every confidence 1.
inline msg::HumanSkeleton SkeletonMessage(const msg::Time& stamp, const std::vector<std::string>& names,
                                          const std::vector<Eigen::Vector3d>& positions, uint32_t body_id = 0) {
  msg::HumanSkeleton s;
  s.header.stamp = stamp;
  s.header.frame_id = "world";
  s.body_id = body_id;
  s.confidence = 1;
  for (std::size_t j = 0; j < positions.size(); ++j) {
    msg::HumanJoint h;
    h.name = names[j];
    h.position = {positions[j].x(), positions[j].y(), positions[j].z()};
    h.confidence = 1;
    s.joints.push_back(h);
  }
  return s;
}

/// A START command of task `task_id` to the joint positions `goal` (rad, the
/// robot's joints in order), then to `retreat` if it is not empty, within
/// `time_limit_s`.
inline msg::TaskCommand JointGoalCommand(uint32_t task_id, const std::string& task_name,
                                         const std::vector<double>& goal, double time_limit_s,
                                         const std::vector<double>& retreat = {}) {
  msg::TaskCommand c;
  c.header.stamp = msg::Now();
  c.task_id = task_id;
  c.task_name = task_name;
  c.command = msg::TaskCommand::START;
  c.goal_type = msg::TaskCommand::GOAL_JOINTS;
  c.goal_positions = goal;
  c.retreat_positions = retreat;
  c.time_limit = time_limit_s;
  return c;
}

/// A trajectory of the Panda's joints from `start`: q_at(t) every `step` s
/// for t in [0, duration] (s, rad).
inline msg::JointTrajectory SampledTrajectory(const msg::Time& start, const std::function<std::vector<double>(double)>& q_at,
                                              double duration, double step = 0.1) {
  msg::JointTrajectory t;
  t.header.stamp = start;
  t.joint_names = kPandaJoints;
  const int n = static_cast<int>(std::lround(duration / step));
  for (int i = 0; i <= n; ++i) {
    msg::JointTrajectoryPoint pt;
    pt.positions = q_at(step * i);
    pt.time_from_start = msg::DurationFromSeconds(step * i);
    t.points.push_back(pt);
  }
  return t;
}

/// The permit a test grants in the supervisor's place (source "test"),
/// stamped now and valid for `validity_s`.
inline msg::SafetyPermit TestPermit(double validity_s = 0.2) {
  msg::SafetyPermit p;
  p.header.stamp = msg::Now();
  p.state = msg::SafetyPermit::PERMIT;
  p.validity = validity_s;
  p.source = "test";
  return p;
}

}  // namespace iplan::testing
