// Collision risk against a person seen only as points (issue 18, the
// depth-camera path; their velocities, issue 29): ISO/TS 15066 separation
// between the robot's spheres and the sensed points, and the parameters of
// the points' layers. The bound itself is iplan/collision/point_bound.h. No
// DDS types.
//
// Separation: S is the surface distance from a robot sphere to a point's
// sphere (radius r_p, around the point's mean); each pair is judged by the
// monitor's pair rule (safety::SsmPairRule: S_p, retreat, speed reduction).
// v_h, the point's speed towards the robot sphere along the unit vector u
// from the point to the sphere: for a point of a tracked part (the cloud
// service's motion estimate, velocity v with covariance C)
//   v_h = max(0, v . u + speed_sigmas sqrt(u^T C u)),
// the measured, directed speed and its uncertainty; for a point not tracked
// the ISO default speed, straight at the sphere. Undirected (directed
// false): v_h = |v| + speed_sigmas sqrt(largest eigenvalue of C), or the
// default. The pair with the smallest margin S - S_p binds (a retreat binds
// with 0). Blocks of points (GaussianPoints::blocks) whose nearest possible
// pair can neither be closer than the closest found, nor bind below the
// binding margin found, nor be inside S_p (or its speed-reduction margin)
// are skipped (S_p is at most its value at the block's largest v_h and the
// sphere's full speed), so the result is that of all pairs.
//
// Frames and units: world frame W, m, m/s, s.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/cell/human_points.h"
#include "iplan/safety/ssm.h"
#include "iplan/collision/point_bound.h"
#include "iplan/core/name_value.h"

namespace iplan::collision_risk {

/// The keys of collision_risk.human_points.
struct PointsParams {
  double horizon = 1.5;            ///< s of the executing trajectory checked against the points
  double time_step = 0.1;          ///< s between the configurations checked
  double min_point_radius = 0.005; ///< m; r_p is max(this, voxel_size / 2)
  double block_size = 0.1;         ///< m; grid of the culling blocks
  /// Whether the separation and the bound use the cloud service's measured
  /// point velocities (issue 29). Off: every point at the ISO default speed,
  /// not moved by the bound (as before issue 29), whatever motions arrive.
  /// Off by default: with them, depth_chain_test's person (a hand reaching
  /// from rest into the arm's path) was touched, -0.03 m; a constant-velocity
  /// estimate of a hand at rest does not bound the speed it reaches within
  /// T_r + T_s (docs/perception-clouds.md, "Not done").
  bool tracked_speeds = false;
  double speed_sigmas = 2.0;       ///< standard deviations of a tracked point's velocity added to its directed speed
  /// s; the bound's prediction moves a tracked point at its velocity for at
  /// most this long (its covariance grows by t^2 C all along the horizon).
  double motion_horizon = 0.5;
  std::string Validate() const;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(horizon, "s of the executing trajectory bounded against the points, > 0"));
    a->Visit(IPLAN_NVP(time_step, "s between the configurations bounded, in (0, horizon]"));
    a->Visit(IPLAN_NVP(min_point_radius, "m; a point's sphere radius is max(this, voxel_size / 2), > 0"));
    a->Visit(IPLAN_NVP(block_size, "m; grid of the blocks points are culled by, > 0"));
    a->Visit(IPLAN_NVP(tracked_speeds, "use the points' measured velocities (speed towards the robot, the bound's motion); false: the ISO default speed for every point"));
    a->Visit(IPLAN_NVP(speed_sigmas, "standard deviations of a tracked point's velocity added to its speed towards the robot, >= 0"));
    a->Visit(IPLAN_NVP(motion_horizon, "s; the bound moves tracked points at their velocity for at most this long (covariance grows all along), >= 0"));
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
  bool binding_tracked = false;     ///< the binding point's speed was measured
  bool retreating = false;          ///< the binding pair is inside S_p, its robot sphere moving away (margin 0)
  /// Speed reduction (safety::SsmPair): the smallest slow and stop scales over the pairs.
  double slow_scale = 1.0, stop_scale = 1.0;
  double margin() const { return retreating ? 0.0 : binding_separation - protective_separation; }
};

/// `points`: the sensed points of `seen` (same order and size), factorised;
/// `seen` gives their motions (checked). p_WS, v_WS: 3 x S robot sphere
/// centres (m) and velocities (m/s), radii S (m). Allocates a little (one
/// bound per block).
PointsSeparation EvaluatePointsSeparation(const collision::GaussianPoints& points, const cell::HumanPoints& seen,
                                          const Eigen::Matrix3Xd& p_WS, const std::vector<double>& radii,
                                          const Eigen::Matrix3Xd& v_WS, const safety::SsmParams& ssm,
                                          double speed_sigmas);

}  // namespace iplan::collision_risk
