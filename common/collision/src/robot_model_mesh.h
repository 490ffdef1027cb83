// The <mesh> collision shapes of a URDF (robot_model.cc): where the file is
// and its spheres in the link frame. Private to iplan::collision.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/collision/robot_model.h"

namespace iplan::collision {

/// The file a URDF <mesh filename> names: relative to the URDF's folder,
/// an absolute path, file://PATH, or package://NAME/REST (REST under a
/// folder NAME on $ROS_PACKAGE_PATH or NAME among the URDF's ancestors).
/// @throws std::runtime_error naming the URDF, the link and where it looked.
std::string ResolveMeshFile(const std::string& urdf_path, const std::string& link, const std::string& filename);

/// Spheres (link frame L) covering the mesh `filename` scaled by `scale`,
/// placed at X_LG; fills `entry` (cover report, mesh file, mesh report).
/// @throws std::runtime_error naming the URDF and the link.
std::vector<Sphere> CoverUrdfMesh(const std::string& urdf_path, const std::string& link, const std::string& filename,
                                  const Eigen::Vector3d& scale, const Eigen::Isometry3d& X_LG,
                                  const RobotModelOptions& options, ShapeCoverEntry* entry);

}  // namespace iplan::collision
