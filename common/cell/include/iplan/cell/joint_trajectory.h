// The robot's joint trajectory in time, as every part of the cell uses it:
// the planner's waypoints, the trajectory a monitor watches, the one the
// robot executes. No DDS types.
//
// Times: `start_ns` is an absolute time (ns since the epoch, the cell's
// clock); `times` are seconds after it. Positions are the robot's
// configuration variables in RobotModel::q_joints order (rad, or m for
// prismatic joints).
//
// Finite differences of waypoints q_0 .. q_n sampled every dt (the planner's
// convention, used by the optimiser, its feasibility check and tests):
//   v_i = (q_{i+1} - q_i) / dt,                  i = 0 .. n-1
//   a_i = (q_{i+1} - 2 q_i + q_{i-1}) / dt^2,     i = 0 .. n,
// with the virtual waypoints q_{-1} = q_0 - qdot_0 dt (the start velocity)
// and q_{n+1} = q_n (the robot stops at the last waypoint).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace iplan::cell {

/// (*index)[w] = position of wanted[w] within `names`, for every wanted
/// name. Returns "missing joint 'x'" for the first wanted name that `names`
/// lacks (then *index is unspecified). Extra names are ignored. Allocates.
std::optional<std::string> MapJointNames(const std::vector<std::string>& names,
                                         const std::vector<std::string>& wanted,
                                         std::vector<int>* index);

struct JointTrajectory {
  int64_t start_ns = 0;                    ///< absolute time of times[i] = 0 (ns)
  std::vector<double> times;               ///< s after start_ns, strictly increasing
  std::vector<Eigen::VectorXd> positions;  ///< one configuration per time (rad / m)

  bool empty() const { return times.empty(); }
  /// The configuration at absolute time t_ns: linear between samples, the
  /// first before the first sample, the last after the last. Requires
  /// !empty(). Allocates the result.
  Eigen::VectorXd PositionAt(int64_t t_ns) const;

  /// Waypoints sampled every dt (s): column i of Q (nq x m) at start_ns + i dt.
  static JointTrajectory Uniform(int64_t start_ns, double dt, const Eigen::MatrixXd& Q);

  /// From wire data: point p has positions points[p] in the order of
  /// `names`; `model_names` are the robot's joints in q order (the result's
  /// order). Returns why it is refused (sizes that differ, a missing joint,
  /// times that do not increase, non-finite values); *out is then
  /// unchanged. Allocates.
  static std::optional<std::string> FromPoints(int64_t start_ns, const std::vector<std::string>& names,
                                               const std::vector<double>& times,
                                               const std::vector<std::vector<double>>& points,
                                               const std::vector<std::string>& model_names,
                                               JointTrajectory* out);
};

/// v_i above for the columns of Q (nq x (n+1)) into *V (nq x n). Allocates
/// *V only when its size changes.
void FiniteDifferenceVelocities(const Eigen::MatrixXd& Q, double dt, Eigen::MatrixXd* V);
/// a_i above for the columns of Q (nq x (n+1)) into *A (nq x (n+1)); qdot0
/// (size nq) is the start velocity. Allocates *A only when its size changes.
void FiniteDifferenceAccelerations(const Eigen::MatrixXd& Q, const Eigen::VectorXd& qdot0, double dt,
                                   Eigen::MatrixXd* A);

}  // namespace iplan::cell
