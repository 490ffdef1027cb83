// Static scene (boxes, cylinders from configuration) and robot-sphere to
// scene distances. FCL does the geometry; it stays in scene.cc (no FCL types
// here), as Drake keeps FCL inside its proximity engine.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace iplan::collision {

/// One static object, in the world frame W (m).
struct SceneObject {
  enum class Shape { kBox, kCylinder };
  std::string name;
  Shape shape = Shape::kBox;
  /// Pose of the object frame O in W. A box is centred on O; a cylinder is
  /// centred on O with its axis along O's z axis.
  Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Ones();  ///< box: full edge lengths (m)
  double radius = 0.0;                             ///< cylinder radius (m)
  double length = 0.0;                             ///< cylinder length (m)
};

struct SceneParams {
  std::vector<SceneObject> objects;
  /// Empty string when valid, else the reason naming the object and value.
  std::string Validate() const;
};

/// Loads a scene from YAML:
///   objects:
///     - {name: table, type: box, xyz: [x, y, z], rpy: [r, p, y], size: [sx, sy, sz]}
///     - {name: pillar, type: cylinder, xyz: [...], rpy: [...], radius: r, length: l}
/// (m, rad; rpy optional, URDF convention R = Rz(y) Ry(p) Rx(r)), read with
/// core::LoadParamsFile (keys declared in scene.cc): unknown and missing keys,
/// wrong types, keys of the other shape and an empty file are errors.
/// @throws std::runtime_error naming the file, object and key.
SceneParams LoadSceneParams(const std::string& path);

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
