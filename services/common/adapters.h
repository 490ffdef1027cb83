// Conversions between message types and the plain types of the algorithm
// cores, shared by the services (the only place where both meet).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "iplan/collision/joint_mixture.h"
#include "iplan/msg/types.h"

namespace iplan::services {

/// The joint-level mixture of a prediction message (covariances row-major).
collision::JointMixture ToJointMixture(const msg::HumanPrediction& m);

/// Trajectory points as (times in s from header.stamp, positions per point).
void FromTrajectory(const msg::JointTrajectory& m, std::vector<double>* times,
                    std::vector<std::vector<double>>* positions);

/// A trajectory message: `positions` is nq x (n + 1), waypoint i at i * dt
/// after `start`.
msg::JointTrajectory ToTrajectory(const msg::Time& start, const std::vector<std::string>& joint_names,
                                  const Eigen::MatrixXd& positions, double dt);

}  // namespace iplan::services
