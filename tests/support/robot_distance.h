// Distances measured from what the robot did: the smallest signed distance
// (m, FCL) of the robot's collision spheres to a static box over a list of
// joint states. Header-only; a test that includes
// it links iplan::collision_fcl.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/collision/static_scene.h"

namespace iplan::testing {

/// Smallest signed distance (m; < 0: inside) of `robot`'s spheres to `box`
/// over `states` (each robot.nq joint positions, model order, rad).
inline double MinDistance(const collision::RobotModel& robot, const collision::SceneObject& box,
                          const std::vector<std::vector<double>>& states) {
  const collision::StaticScene scene(collision::SceneParams{{box}});
  collision::RobotData d(robot);
  std::vector<double> radii;
  for (const auto& s : robot.spheres) radii.push_back(s.radius);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& q : states) {
    collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(q.data(), robot.nq), &d);
    best = std::min(best, scene.CalcMinimumDistance(d.p_WS, radii).distance);
  }
  return best;
}

}  // namespace iplan::testing
