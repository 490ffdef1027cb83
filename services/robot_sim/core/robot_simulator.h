// A simulated robot arm: follows a time-stamped joint trajectory at the
// control rate within the joint position, velocity and acceleration limits,
// obeys protective stop / resume with a configured stopping time and speed
// reduction (its path time-scaled), and counts true contacts between its
// collision spheres and a person's true body.
// No DDS types. Units: rad, rad/s, rad/s^2, s, m; times in ns since the epoch.
// Not thread-safe (one owner).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/cell/joint_trajectory.h"
#include "iplan/safety/ssm.h"
#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"

#include "iplan/core/name_value.h"

namespace iplan::robot_sim {

struct SimulatorParams {
  double stopping_time = 0.3;  ///< s, T_s: a protective stop brings every joint to rest within it
  /// How hard a protective stop brakes: every joint decelerates uniformly
  /// and all reach rest together (the arm stays on its path, a controlled
  /// stop on the drives: ISO 10218-1 category 2), within the time the
  /// slowest joint needs at this fraction of its acceleration limit, and
  /// never later than stopping_time. 0: every stop takes stopping_time,
  /// whatever the speed. In [0, 1].
  double braking_fraction = 0.0;
  double contact_margin = 0.0; ///< m; spheres closer than this count as touching
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(stopping_time, "s; T_s, a protective stop brings every joint to rest within it, > 0"));
    a->Visit(IPLAN_NVP(braking_fraction, "a stop brakes all joints together, the slowest at this fraction of its acceleration limit (at most stopping_time; 0: always stopping_time), in [0, 1]"));
    a->Visit(IPLAN_NVP(contact_margin, "m; spheres closer than this count as touching, >= 0"));
  }
  /// Empty when valid, else the reason.
  std::string Validate() const;
};

/// A trajectory to follow: points at `times` (s after start_ns).
class RobotSimulator {
 public:
  /// `q0`: initial configuration (model joint order). Throws
  /// std::invalid_argument on a wrong size, a position outside the limits or
  /// invalid params.
  RobotSimulator(collision::RobotModel robot, const Eigen::VectorXd& q0, SimulatorParams params);

  /// Replaces the trajectory being followed. Returns why it was refused
  /// (unknown joint names, non-increasing times, points outside the limits).
  std::optional<std::string> SetTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                           const std::vector<double>& times,
                                           const std::vector<std::vector<double>>& positions);
  /// Protective stop: decelerate every joint to rest, all at the same
  /// moment, within stopping_time (sooner with braking_fraction > 0).
  void Stop();
  /// Resume following the trajectory (from where its timing says it is now).
  void Resume();
  bool stopped() const { return stop_requested_; }
  /// ISO/TS 15066 speed reduction: follow the trajectory's path at `scale`
  /// (clamped to [0, 1]) of its timing from now on, i.e. its time runs
  /// `scale` s per s and falls behind the clock (the tracking within the
  /// limits brings the joints to the slower path speed). A new trajectory
  /// starts on time again (the replanner plans from where the robot is).
  void SetSpeedScale(double scale);
  double speed_scale() const { return speed_scale_; }
  /// s the trajectory's time is behind the clock (speed reduction).
  double path_lag() const { return lag_ns_ * 1e-9; }

  /// Advances the simulation to `now_ns` by one control step of `dt` s:
  /// tracks the trajectory's position at now_ns within velocity and
  /// acceleration limits (or decelerates when stopped).
  void Step(int64_t now_ns, double dt);

  /// Checks the robot's spheres against the person's true body (joint
  /// positions in body joint order, 3 x J). Returns the minimum surface
  /// distance (m) and counts a contact when it goes below contact_margin
  /// (a contact is counted once per episode of touching).
  double UpdateContacts(const Eigen::Matrix3Xd& true_joints, const collision::HumanBodyModel& body);

  const Eigen::VectorXd& q() const { return q_; }
  const Eigen::VectorXd& qd() const { return qd_; }
  /// The robot's joints in q order (what joint states and trajectories carry).
  const std::vector<std::string>& joint_names() const { return robot_joints_; }
  int contacts() const { return contacts_; }
  /// Smallest separation UpdateContacts has seen (m); nullopt before the first.
  const safety::Separation& min_separation_seen() const { return min_separation_seen_; }
  /// s the last stop took (or takes) from its command to rest.
  double last_stop_duration() const { return last_stop_duration_; }
  /// Max over the last stop of the end-effector (last sphere) travel after the stop command (m).
  double last_stopping_distance() const { return last_stopping_distance_; }
  const collision::RobotModel& robot() const { return robot_; }

 private:
  Eigen::VectorXd Desired(int64_t now_ns) const;

  collision::RobotModel robot_;
  SimulatorParams params_;
  collision::RobotData data_;
  Eigen::VectorXd q_, qd_;
  Eigen::VectorXd lower_, upper_, vmax_, amax_;
  std::vector<std::string> robot_joints_;  // robot_.JointNames()
  cell::JointTrajectory trajectory_;      // empty: hold the current position
  bool stop_requested_ = false;
  double speed_scale_ = 1.0;
  int64_t lag_ns_ = 0;  // trajectory time = clock - lag (speed reduction)
  Eigen::VectorXd stop_decel_;  // per joint deceleration of the current stop
  Eigen::Vector3d stop_start_ee_ = Eigen::Vector3d::Zero();
  double last_stopping_distance_ = 0;
  double last_stop_duration_ = 0;
  bool touching_ = false;
  int contacts_ = 0;
  safety::Separation min_separation_seen_;
};

}  // namespace iplan::robot_sim
