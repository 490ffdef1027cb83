// The static scene as FCL objects: exact signed distances between spheres
// and the scene's boxes and cylinders, for verification and for the geometry
// the planner's analytic primitives do not cover (meshes, octrees of
// unknown obstacles). Target iplan::collision_fcl: only what uses it links
// FCL. The trajectory optimiser uses its own analytic distances
// (common/planning/src/clearance.h, about 15 times faster, with gradients;
// planning_bench prints both), which the tests check against this class.
// Frames and units: positions in W, m.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/scene.h"

namespace iplan::collision {

/// Closest pair between robot spheres and the scene.
struct SceneDistance {
  /// Signed distance (m): > 0 separation, < 0 penetration depth. +infinity
  /// for an empty scene or no spheres.
  double distance = 0.0;
  int sphere = -1;  ///< index of the robot sphere
  int object = -1;  ///< index into SceneParams::objects
};

/// Immutable scene. Const methods are thread-safe. Queries allocate (FCL
/// query objects); do not use them in a real-time loop.
class StaticScene {
 public:
  /// @throws std::invalid_argument with the reason if params are invalid.
  explicit StaticScene(SceneParams params);
  ~StaticScene();
  StaticScene(StaticScene&&) noexcept;
  StaticScene& operator=(StaticScene&&) noexcept;

  const SceneParams& params() const;
  int num_objects() const;

  /// Signed distance (m) between the sphere (centre p_WS in W, radius >= 0)
  /// and object `object`: > 0 apart, < 0 penetration depth.
  double CalcSignedDistance(int object, const Eigen::Vector3d& p_WS, double radius) const;

  /// Minimum signed distance over all spheres (centres 3 x n in W, radii n)
  /// and objects.
  SceneDistance CalcMinimumDistance(const Eigen::Matrix3Xd& p_WS,
                                    const std::vector<double>& radii) const;

  /// True if some sphere comes closer than `margin` (m) to some object.
  bool CheckCollision(const Eigen::Matrix3Xd& p_WS, const std::vector<double>& radii,
                      double margin = 0.0) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace iplan::collision
