// The oriented box around a set of points: with an "up" direction (the
// table's normal: objects stand on it) the box's z axis is up and its yaw
// about it gives the smallest footprint (a rotated bin is reported as large
// as it is, not as the larger axis-aligned box around it); without one,
// the principal axes of the points (PCA).
//
// Frame: the points' frame F (the sensor's S, or the cell's W); metres.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace iplan::cloud {

/// A box in frame F: the box frame B has its origin at the centre and its
/// axes along the box's edges.
struct OrientedBox {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();                 ///< p_FB, metres
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();  ///< R_FB, unit
  Eigen::Vector3f half_extents = Eigen::Vector3f::Zero();           ///< along B's x, y, z; metres, >= 0
};

/// The box around points[i] for i in `indices` (all finite). With `up`
/// (unit, in F): B's z axis is `up`, B's x axis the longer side of the
/// footprint (the points projected along up) whose yaw about up minimises
/// the footprint's area (searched over 90 degrees to 0.25 degree on at
/// most 256 of the points, evenly spread) and x_B . x_F >= 0 (x_B . y_F
/// >= 0 when up is along x_F), so a box keeps its axes from frame to
/// frame; the extents then hold every point. Without `up`: B's axes are
/// the points' principal axes (largest variance first, x_B . x_F >= 0,
/// y_B . y_F >= 0, z_B = x_B x y_B), the extents again holding every point. Empty indices give a zero box at
/// the origin. Deterministic; allocates only for the sample; thread-safe.
OrientedBox FitOrientedBox(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices,
                           const Eigen::Vector3f* up);

}  // namespace iplan::cloud
