// Collision risk against a person seen only as points (issue 18, the
// depth-camera path): ISO/TS 15066 separation between the robot's spheres
// and the sensed points, and the parameters of the points' layers. The bound
// itself is iplan/collision/point_bound.h. No DDS types.
//
// Separation: S is the surface distance from a robot sphere to a point's
// sphere (radius r_p, around the point's mean); S_p as for the skeleton
// (iplan/cell/ssm.h), with v_h the ISO default speed (points carry no
// measurable speed) and, when directed, v_r the robot sphere's speed towards
// the point. The pair with the smallest S - S_p binds. Blocks of points
// (GaussianPoints::blocks) whose nearest possible pair can neither be closer
// than the closest found nor bind below the binding margin found are
// skipped (S_p is at most its value at the sphere's full speed), so the
// result is that of all pairs.
//
// Frames and units: world frame W, m, m/s, s.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/cell/ssm.h"
#include "iplan/collision/point_bound.h"
#include "iplan/core/name_value.h"

namespace iplan::collision_risk {

/// The keys of collision_risk.human_points.
struct PointsParams {
  double horizon = 1.5;            ///< s of the executing trajectory checked against the points
  double time_step = 0.1;          ///< s between the configurations checked
  double min_point_radius = 0.005; ///< m; r_p is max(this, voxel_size / 2)
  double block_size = 0.1;         ///< m; grid of the culling blocks
  std::string Validate() const;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(horizon, "s of the executing trajectory bounded against the points, > 0"));
    a->Visit(IPLAN_NVP(time_step, "s between the configurations bounded, in (0, horizon]"));
    a->Visit(IPLAN_NVP(min_point_radius, "m; a point's sphere radius is max(this, voxel_size / 2), > 0"));
    a->Visit(IPLAN_NVP(block_size, "m; grid of the blocks points are culled by, > 0"));
  }
};

/// The binding and the closest pair of robot sphere and point.
struct PointsSeparation {
  bool any = false;                 ///< false: no points (nothing else is set)
  double min_separation = 0;        ///< m, smallest surface distance
  int closest_sphere = -1;
  double binding_separation = 0;    ///< m, S of the binding pair
  double protective_separation = 0; ///< m, its S_p
  double human_speed = 0, robot_speed = 0;  ///< m/s in that S_p
  int binding_sphere = -1;
  int binding_point = -1;           ///< input index of the binding point
  double margin() const { return binding_separation - protective_separation; }
};

/// p_WS, v_WS: 3 x S robot sphere centres (m) and velocities (m/s), radii S (m).
PointsSeparation EvaluatePointsSeparation(const collision::GaussianPoints& points, const Eigen::Matrix3Xd& p_WS,
                                          const std::vector<double>& radii, const Eigen::Matrix3Xd& v_WS,
                                          const cell::SsmParams& ssm);

}  // namespace iplan::collision_risk
