// Jacobians and inverse kinematics on top of iplan::collision::RobotModel.
// Frames: W world (= robot root); poses X_WE of the end effector E, a point
// fixed to a link. SI units (m, rad).
#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/collision/robot_model.h"

namespace iplan::planning {

/// Precomputed joint chains of a robot model: for every link, the joints
/// (and their configuration indices) that move it. Immutable; thread-safe.
class KinematicChains {
 public:
  struct Entry {
    int joint = -1;           ///< index into model.joints
    int q_index = -1;         ///< configuration variable the joint follows
    double multiplier = 1.0;  ///< d(joint value)/d(q[q_index]) (mimic joints)
    bool revolute = true;
  };
  /// Allocates. Keeps a reference to `model`, which must outlive this object.
  explicit KinematicChains(const collision::RobotModel& model);
  const collision::RobotModel& model() const { return *model_; }
  const std::vector<Entry>& chain(int link) const { return chains_[link]; }

  /// Translational Jacobian (3 x nq, m/rad) of the point p_WP (m, W) fixed to
  /// `link`, at the configuration of `data` (CalcForwardKinematics done).
  /// J must be 3 x nq. Does not allocate.
  void CalcPointJacobian(const collision::RobotData& data, int link, const Eigen::Vector3d& p_WP,
                         Eigen::Ref<Eigen::Matrix<double, 3, Eigen::Dynamic>> J) const;
  /// Adds J^T g to grad_q (size nq) for the point p_WP fixed to `link` and a
  /// gradient g = dC/dp_WP (unit of C per m). Does not allocate.
  void AddPointGradient(const collision::RobotData& data, int link, const Eigen::Vector3d& p_WP,
                        const Eigen::Vector3d& g, Eigen::Ref<Eigen::VectorXd> grad_q) const;
  /// Rotational Jacobian (3 x nq, rad/rad, world frame) of `link`.
  void CalcRotationJacobian(const collision::RobotData& data, int link,
                            Eigen::Ref<Eigen::Matrix<double, 3, Eigen::Dynamic>> J) const;

 private:
  const collision::RobotModel* model_;
  std::vector<std::vector<Entry>> chains_;
};

/// Inverse-kinematics settings (see PlannerParams for defaults).
struct IkOptions {
  int max_iterations = 200;
  double damping = 0.05;               ///< DLS damping lambda (m)
  double position_tolerance = 1e-4;    ///< m
  double orientation_tolerance = 1e-3; ///< rad
  int restarts = 8;                    ///< extra attempts from random seeds
  double position_margin = 1e-3;       ///< solutions stay this far inside limits (rad)
  /// Non-zero: only this axis of the link (unit, link frame) must point the
  /// way the target's same axis does (X_WE_target.linear() * align_axis_L);
  /// rotation about it is free (a tool that may turn about its own axis).
  /// Zero: the whole orientation.
  Eigen::Vector3d align_axis_L = Eigen::Vector3d::Zero();
};

struct IkResult {
  bool success = false;
  Eigen::VectorXd q;              ///< best configuration found (size nq)
  double position_error = 0.0;    ///< m
  double orientation_error = 0.0; ///< rad
  int iterations = 0;             ///< total over restarts
};

/// Damped least squares (Levenberg-Marquardt) IK for the pose X_WE_target of
/// the point p_LE (m) fixed to `link` with the link's orientation:
/// dq = J^T (J J^T + lambda^2 I)^-1 e, e = [p error (m); rotation vector of
/// R_target R^T (rad)], steps capped at 0.5 rad, q clamped to the limits
/// shrunk by position_margin. Starts from q_seed, then from `restarts`
/// configurations drawn uniformly in the limits with `rng`.
/// @throws std::invalid_argument on bad sizes, link index or non-finite input.
/// Thread-safe for distinct rng; allocates.
IkResult SolveIk(const KinematicChains& chains, int link, const Eigen::Vector3d& p_LE,
                 const Eigen::Isometry3d& X_WE_target, const Eigen::VectorXd& q_seed,
                 const IkOptions& options, std::mt19937_64* rng);

}  // namespace iplan::planning
