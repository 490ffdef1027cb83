// A peer planner for the planning benchmark (issue 17): OMPL's RRTConnect
// with path simplification, on the same robot, scene and collision model as
// iplan's planner (Planner::CalcClearance >= min_clearance is the state
// validity check), then a time parameterisation within the same joint
// limits. Benchmark only: OMPL is not a dependency of any iplan library or
// service, and its types stay in ompl_peer.cc.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "iplan/planning/planner.h"

namespace iplan::planning::bench {

struct PeerResult {
  bool solved = false;
  double time_to_solution = 0.0;  ///< s, wall time of RRTConnect until its (first) solution
  double planning_time = 0.0;     ///< s, that plus path simplification
  /// The simplified path time-parameterised rest-to-rest per segment (each
  /// segment a trapezoidal profile at the planner's limit_scale x joint
  /// velocity and acceleration limits, all joints synchronised), sampled
  /// every PlannerParams::dt: nq x (n + 1), rad. Empty when not solved.
  Eigen::MatrixXd positions;
};

/// Plans from `start` to `goal` (nq joint values each, rad) within
/// `time_limit` s. OMPL's global random seed is set from `seed` on the first
/// call only (OMPL allows that once per process).
PeerResult PlanWithRrtConnect(const Planner& planner, const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                              double time_limit, std::uint64_t seed);

}  // namespace iplan::planning::bench
