// The people the depth camera sees, as the cell's services take them from
// the cloud service (/iplan/human/points; docs/perception-clouds.md): sensed
// points, each a Gaussian (the sensor's noise at its depth), and the tracked
// velocity of the part of a person each belongs to (issue 29; the cloud
// service's constant-velocity Kalman filters). A point of no tracked part
// has no measured speed: the ISO/TS 15066 default applies to it.
//
// Frame: the cell frame W (`world`); m, m/s, m^2, (m/s)^2; stamps in ns
// since the epoch. No DDS types.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace iplan::cell {

/// The tracked velocity of a part of a person, W.
struct PointMotion {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();    ///< m/s
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< (m/s)^2, symmetric positive semi-definite
  uint32_t id = 0;  ///< the tracked part's, >= 1 and stable while it is tracked; 0: not known
};

struct HumanPoints {
  int64_t stamp_ns = 0;      ///< when the cloud was taken
  double voxel_size = 0.0;   ///< m, the grid the points were reduced on (0: not reduced)
  Eigen::Matrix3Xd means = Eigen::Matrix3Xd(3, 0);  ///< m, 3 x n
  std::vector<Eigen::Matrix3d> covariances;         ///< m^2, n
  /// Per point the index into `motions` of its part, -1 when it is not
  /// tracked; empty: no point is tracked.
  std::vector<int> motion_of;
  std::vector<PointMotion> motions;

  int size() const { return static_cast<int>(means.cols()); }
  /// The index into `motions` of point i's part, -1 when it is not tracked
  /// (i in [0, size())).
  int MotionIndexOf(int i) const {
    return i < static_cast<int>(motion_of.size()) ? motion_of[static_cast<std::size_t>(i)] : -1;
  }
  /// Point i's motion, null when it is not tracked (i in [0, size())).
  const PointMotion* MotionOf(int i) const {
    const int k = MotionIndexOf(i);
    return k >= 0 ? &motions[static_cast<std::size_t>(k)] : nullptr;
  }
  /// Why the points are inconsistent (sizes, a motion index out of range, a
  /// velocity not finite, a velocity covariance not symmetric positive
  /// semi-definite), nullopt when they are not. The point covariances are
  /// the consumer's to check (a bound needs them positive definite).
  std::optional<std::string> Check() const;
};

}  // namespace iplan::cell
