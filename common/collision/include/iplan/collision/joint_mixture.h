// A predicted person at joint level, the cell's one prediction type: per
// action a probability and per future step and joint a Gaussian. The intent
// core predicts into it, the intent service publishes it (the adapters
// convert it to and from /iplan/human/prediction), and the collision-risk
// monitor and the replanner build the sphere-level HumanPrediction the
// bound works on from it (BuildSpherePrediction; cell::TimedPrediction adds
// the step times).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/human_model.h"
#include "iplan/collision/trajectory_bound.h"

namespace iplan::collision {

/// A Gaussian for one joint at one future step: mean p_WJ (m) and
/// covariance (m^2), frame W.
struct JointGaussian {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

struct JointMixture {
  int64_t t0_ns = 0;       ///< time of the observation it starts from (ns since the epoch)
  double time_step = 0;    ///< s; step k (0-based) is at t0 + (k + 1) time_step
  int num_steps = 0;
  /// (J) the joints' names; empty where only their order is known (the
  /// intent core's baseline predictors: the service names them).
  std::vector<std::string> joint_names;
  std::vector<std::string> actions;   ///< (A) action labels
  std::vector<double> probabilities;  ///< (A) p(action | observation), sum 1
  /// [action][step * J + joint]: mean (m, world frame) and covariance (m^2).
  std::vector<std::vector<Eigen::Vector3d>> means;
  std::vector<std::vector<Eigen::Matrix3d>> covariances;

  int num_actions() const { return static_cast<int>(probabilities.size()); }
  /// J, from the sizes (num_steps > 0 and at least one action), else 0.
  int num_joints() const {
    return num_steps > 0 && !means.empty() ? static_cast<int>(means[0].size()) / num_steps : 0;
  }
  const Eigen::Vector3d& Mean(int action, int step, int joint) const {
    return means[static_cast<std::size_t>(action)][static_cast<std::size_t>(step * num_joints() + joint)];
  }
  const Eigen::Matrix3d& Covariance(int action, int step, int joint) const {
    return covariances[static_cast<std::size_t>(action)][static_cast<std::size_t>(step * num_joints() + joint)];
  }
  /// Sizes for `num_actions` actions, `num_steps` steps and `num_joints`
  /// joints (actions and probabilities too): values kept where there were
  /// some, new Gaussians zero. Allocates only when the sizes grow.
  void Resize(int num_actions, int num_steps, int num_joints);
  /// Moment-matched single Gaussian of the mixture for (step, joint):
  /// mean = sum p_a mu_a, covariance = sum p_a (Sigma_a + mu_a mu_a^T) - mean mean^T.
  JointGaussian Combined(int step, int joint) const;
  /// Index of the most probable action (the first of equals), 0 when empty.
  int MostLikely() const;
};

/// Fills `out` (allocated here for the body's spheres) from `in`, picking the
/// body model's joints by name. Returns why it cannot (no actions, sizes that
/// do not match, a missing joint, a sphere covariance that is not positive
/// definite); `out` is then unspecified. Allocates.
std::optional<std::string> BuildSpherePrediction(const HumanBodyModel& body, const JointMixture& in,
                                                 HumanPrediction* out);

}  // namespace iplan::collision
