// Analytic signed distances between points and the scene's boxes and
// cylinders, with gradients. Used by the optimiser instead of FCL queries
// (which allocate and have no gradient); tests verify the results with FCL.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/collision/scene.h"

namespace iplan::planning::internal {

struct ClearanceObject {
  bool box = true;
  Eigen::Isometry3d X_OW = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R_WO = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d half = Eigen::Vector3d::Zero();  ///< box half extents (m)
  double radius = 0.0;                             ///< cylinder radius (m)
  double half_length = 0.0;                        ///< cylinder half length (m)
  double bounding_radius = 0.0;                    ///< ball around the object (m)
};

ClearanceObject MakeClearanceObject(const collision::SceneObject& o);

/// Signed distance (m) from the point p_W to the object's surface (< 0
/// inside) and its gradient d(distance)/d(p_W) (unit vector, W). Pure.
double PointSignedDistance(const ClearanceObject& o, const Eigen::Vector3d& p_W,
                           Eigen::Vector3d* grad_W);

}  // namespace iplan::planning::internal
