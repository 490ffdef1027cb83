// A static object the depth camera sees that no model knows (a box left on
// the table), as the cloud service reports it and trajectory optimisation
// plans around it (/iplan/obstacles; docs/perception-clouds.md): a box B
// in the cell frame, kept while the cloud service tracks the object.
//
// Frame: the cell frame W (`world`); m; stamps in ns since the epoch. No
// DDS types.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace iplan::cell {

struct ObstacleBox {
  uint32_t id = 0;                                                  ///< >= 1, stable while tracked
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();                 ///< m, p_WB
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< R_WB, unit
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();           ///< m along B's axes, >= 0
  int points = 0;              ///< cloud points supporting it at its last sighting
  int64_t first_seen_ns = 0;   ///< stamp of the first cloud it was seen in
};

}  // namespace iplan::cell
