// Shared fixtures of the planning tests and benchmark: the Panda in the
// default cell, table-top poses, and synthetic predictions of a person.
#pragma once

#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/planning/planner.h"

namespace iplan::planning::testing {

collision::RobotModel LoadPanda();
collision::SceneParams LoadCell();

/// The Panda's ready configuration the planning tests start from (rad).
Eigen::VectorXd Ready();

/// Flange pointing down (z of the flange along -z of W), yaw `yaw` (rad).
Eigen::Quaterniond DownOrientation(double yaw);

/// Named table-top flange positions (m, W): table, shelf height, above the bin.
struct NamedPose {
  const char* name;
  Eigen::Vector3d p;
};
std::vector<NamedPose> TableTopPoses();

/// The sweep many planner tests plan: the gripper pointing down at 0.30 m,
/// across the table from (0.45, -0.35) to (0.45, 0.15) m (W), as a request
/// from the start configuration to the joint goal, both from `planner`'s
/// IK seeded at Ready(); nullopt when either has no IK solution.
std::optional<PlanningRequest> AcrossTheTable(const Planner& planner);

/// A person standing across the table from the robot (at x = 1.15 m)
/// reaching with the right hand towards `reach_targets` (one action each,
/// probabilities decreasing geometrically, normalised). Step s at time
/// s * dt; the hand moves from its rest pose to the target over the steps.
/// Joint covariances grow linearly with time from sigma0^2 to sigma1^2 (m^2),
/// isotropic. Allocates.
collision::HumanPrediction MakeReachingPrediction(const collision::HumanBodyModel& body,
                                                  const std::vector<Eigen::Vector3d>& reach_targets,
                                                  int num_steps, double sigma0 = 0.02,
                                                  double sigma1 = 0.08,
                                                  Eigen::Vector3d torso_offset = Eigen::Vector3d::Zero());

}  // namespace iplan::planning::testing
