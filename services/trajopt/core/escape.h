// Getting out of the person's way when no safe plan exists (docs/planning.md,
// "Escaping"). The collision-risk monitor does not stop a trajectory that
// lowers the bound within its stop horizon by at least bound_retreat_gain
// against the robot standing still (RiskParams::bound_retreat_gain): a stop
// there would leave the robot where the person is predicted to come. The
// replanner predicts that rule: when the robot held where it stands would
// reach the bound within the horizon and no plan keeps below it, it takes
// the candidate plan that lowers the bound most, if the monitor would let it
// run. No DDS types. Units: s, m, rad; frames: world (= robot base).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/planning/planner.h"

namespace iplan::trajopt {

struct EscapeParams {
  /// s after waypoint 0 over which bounds are compared (the monitor's
  /// stop_horizon); <= 0: escaping is off.
  double horizon = 1.0;
  /// The least drop of the largest bound within the horizon, against
  /// standing still, that makes a plan an escape (the monitor's
  /// bound_retreat_gain); 0: off.
  double gain = 0.05;
  /// m the end effector is moved by each aside goal.
  double distance = 0.25;
};

/// Largest bound (union over the request's people) within `horizon` s of
/// waypoint 0 for the robot held at `q` (rad), with the planner's timing of
/// each person's prediction (planner.h, "Prediction timing"). 0 without
/// people. Allocates.
double HoldBound(const planning::Planner& planner, const planning::PlanningRequest& req, const Eigen::VectorXd& q,
                 double horizon);

/// Largest of `bounds` (PlanningResult::bounds, per waypoint at dt) within
/// `horizon` s of waypoint 0.
double HorizonBound(const std::vector<double>& bounds, double dt, double horizon);

/// The end effector (PlannerParams::end_effector_link and offset) at q (rad):
/// its pose in W and the horizontal vector (m, W, z = 0, not normalised)
/// from the predicted human sphere nearest to it, over every step of every
/// action and person, or over each one's last step only. nullopt without
/// people or an end-effector link.
struct AwayFromPerson {
  Eigen::Vector3d p_WE;
  Eigen::Quaterniond R_WE;
  Eigen::Vector3d away;
};
std::optional<AwayFromPerson> FindAwayFromPerson(const planning::Planner& planner, const planning::PlanningRequest& req,
                                                 const Eigen::VectorXd& q, bool last_step_only);

/// Joint goals (rad) out of the person's way from q (rad): the end effector,
/// its orientation kept, `distance` m horizontally away from the predicted
/// human sphere nearest to it over the prediction, away and up, straight
/// up, and back towards the robot's base (those IK solves), then each of
/// the first four joints turned by +-0.4 rad within its limits. Empty
/// without people.
std::vector<Eigen::VectorXd> AsideGoals(const planning::Planner& planner, const planning::PlanningRequest& req,
                                       const Eigen::VectorXd& q, double distance);

/// A plan that may escape: feasible (limits, static clearance) and lowering
/// the largest bound within the horizon by at least params.gain against
/// `hold_bound`. Of `failed` (the cycle's own best attempt) and plans to the
/// aside goals (each planned from `req` with its goal replaced), the one of
/// lowest horizon bound; nullopt when none qualifies. `time_budget` (s of
/// wall time, 0: none) is shared by the aside goals' plans: each gets what
/// is left over the goals still to plan, and none starts once it is spent
/// (with a budget the result depends on timing, as PlanningRequest's does).
std::optional<planning::PlanningResult> FindEscape(const planning::Planner& planner, planning::PlanningRequest req,
                                                   const planning::PlanningResult& failed, const Eigen::VectorXd& q,
                                                   double hold_bound, const EscapeParams& params,
                                                   double time_budget = 0.0);

}  // namespace iplan::trajopt
