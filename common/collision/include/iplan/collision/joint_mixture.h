// A predicted person at joint level (what the intent service publishes: per
// action a probability and per future step and joint a Gaussian), and its
// conversion to the sphere-level HumanPrediction the bound works on.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/human_model.h"
#include "iplan/collision/trajectory_bound.h"

namespace iplan::collision {

struct JointMixture {
  int64_t t0_ns = 0;       ///< time of the observation it starts from (ns since the epoch)
  double time_step = 0;    ///< s; step k (0-based) is at t0 + (k + 1) time_step
  int num_steps = 0;
  std::vector<std::string> joint_names;
  std::vector<std::string> actions;
  std::vector<double> probabilities;
  /// [action][step * J + joint]: mean (m, world frame) and covariance (m^2).
  std::vector<std::vector<Eigen::Vector3d>> means;
  std::vector<std::vector<Eigen::Matrix3d>> covariances;
};

/// Fills `out` (allocated here for the body's spheres) from `in`, picking the
/// body model's joints by name. Returns why it cannot (no actions, sizes that
/// do not match, a missing joint, a sphere covariance that is not positive
/// definite); `out` is then unspecified. Allocates.
std::optional<std::string> BuildSpherePrediction(const HumanBodyModel& body, const JointMixture& in,
                                                 HumanPrediction* out);

}  // namespace iplan::collision
