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

}  // namespace iplan::collision
