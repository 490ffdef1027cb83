// The person seen only by the depth camera, as a prediction the planner
// already understands (issue 29): the human points (cell::HumanPoints, the
// cloud service's, with the tracked velocity of each point's part) coarsened
// into spheres, one sphere per occupied cell of a sphere_size grid within
// each part (a point of no tracked part: within the untracked ones), and
// predicted at constant velocity with growing covariance:
//
//   step k (0-based) at t_k = (k + 1) time_step after the cloud's stamp
//   (the cell's convention, iplan/cell/timed_prediction.h):
//     mean_k       = c + min(t_k, motion_horizon) v
//     covariance_k = S + t_k^2 C
//
// c the centroid of the cell's points, S their mean noise covariance (at
// least (1 mm)^2 per axis), v and C the part's velocity and its covariance
// (0 for untracked points: they stay where they were seen); the radius
// covers every point of the cell, max |p - c| + max(voxel_size / 2, 5 mm).
// What the separation monitor adds to the part's speed and the planner's
// mean motion does not show is the sphere's speed allowance
// (HumanPrediction::speed_allowance): collision risk judges a tracked point
// at v . u + speed_sigmas sqrt(u^T C u), an untracked one at the ISO default
// speed, so the allowance is speed_sigmas sqrt(the largest eigenvalue of C),
// or default_human_speed; the planner's predicted monitor adds it to the
// mean motion towards the robot, so its margin is never above the monitor's.
// (Until 2026-12-06 the radius was grown by (T_r + T_s) x the allowance
// instead: the same separation prediction, but the bound and the keep-out
// then saw a person 0.6 m larger than seen, and the camera-only demo's
// planner held the arm at 0.9 m from a person standing still.)
// One action ("as seen") of probability 1. So the planner's bound, its
// keep-out and its prediction of the separation monitor (which takes the
// human speed from consecutive steps' means) see the measured, directed
// motion of each part. Coarse, so that a replanning cycle against a person
// of a few hundred points stays within its budget; more than max_spheres
// and the grid is doubled until they fit. A 0.1 m grid (up to 96 spheres):
// the 0.2 m grid of before gave spheres of up to 17 cm radius, and the
// planner's bound beside a person standing at the hand-over was 0.04-0.06
// against the monitor's 0.004 (the demo's hand-over waited on it); with
// 0.1 m it was 0.01-0.02, planning p99 44-47 ms of the 50 ms budget
// (docs/perception-clouds.md, "The camera-only cell").
//
// Frames and units: world frame W, m, s. No DDS types.
#pragma once

#include <optional>
#include <string>

#include "iplan/cell/human_points.h"
#include "iplan/safety/ssm.h"
#include "iplan/collision/trajectory_bound.h"
#include "iplan/core/name_value.h"

namespace iplan::trajopt {

struct PointsPredictionParams {
  double sphere_size = 0.1;     ///< m, grid the points of each part are coarsened on
  double time_step = 0.1;       ///< s between prediction steps
  double horizon = 1.5;         ///< s, time of the last step
  double motion_horizon = 0.5;  ///< s a tracked part moves at its velocity (its covariance grows all along)
  int max_spheres = 96;         ///< at most this many spheres (the grid coarsens)
  /// As collision_risk.yaml human_points.tracked_speeds (keep them equal):
  /// false, every sphere is untracked (where seen, grown by the ISO speed).
  bool tracked_speeds = false;
  double speed_sigmas = 2.0;    ///< as collision_risk.yaml human_points.speed_sigmas (keep them equal)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(sphere_size, "m, grid the points of each tracked part are coarsened on into spheres, > 0"));
    a->Visit(IPLAN_NVP(time_step, "s between the prediction's steps, > 0"));
    a->Visit(IPLAN_NVP(horizon, "s, time of the prediction's last step, >= time_step"));
    a->Visit(IPLAN_NVP(motion_horizon, "s a tracked part moves at its velocity in the prediction (its covariance grows all along), >= 0"));
    a->Visit(IPLAN_NVP(max_spheres, "at most this many spheres (the grid coarsens), >= 1"));
    a->Visit(IPLAN_NVP(tracked_speeds, "use the parts' measured velocities, as collision_risk's human_points.tracked_speeds; false: every sphere where seen, at the ISO speed"));
    a->Visit(IPLAN_NVP(speed_sigmas, "velocity standard deviations the monitor adds to a tracked point's speed: collision_risk's human_points.speed_sigmas, >= 0"));
  }
  /// Empty when valid, else the first problem.
  std::string Validate() const;
};

/// The sphere prediction of `seen` (checked by the caller: seen.Check());
/// `ssm` the separation monitor's parameters the planner predicts (T_r, T_s,
/// the default human speed). nullopt when there are no points (nobody
/// seen). Allocates.
std::optional<collision::HumanPrediction> BuildPointsPrediction(const PointsPredictionParams& params,
                                                                const cell::HumanPoints& seen,
                                                                const safety::SsmParams& ssm);

}  // namespace iplan::trajopt
