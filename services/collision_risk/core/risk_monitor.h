// The collision-risk monitor: the cell's independent watchdog on the robot
// trajectory that is actually executing. No DDS types.
//
// Two layers (METHOD 4 and 7):
//  - prediction: the upper bound of P(contact) between the robot's spheres
//    along the executing trajectory and the predicted human (Gaussian mixture
//    over actions), per prediction step, from iplan::collision;
//  - ISO/TS 15066 speed and separation monitoring, independent of any
//    prediction: the current minimum robot-human surface distance against the
//    protective separation distance
//      S_p = v_h (T_r + T_s) + v_r T_r + S_s + C + Z_d + Z_r.
// With `directed` (the default, as ISO/TS 15066 defines the speeds) S_p is
// evaluated per pair of robot and human spheres: v_h is the human sphere's
// speed towards the robot sphere, v_r the robot sphere's speed towards the
// human sphere, and S_s scales with that speed, S_s * min(1, v_r / v_s)
// with v_s the speed at which the stopping distance was measured (linear in
// the speed, so above the v^2 of a constant deceleration below v_s; a robot
// at rest or moving away travels nothing towards the person while it stops).
// So a stopped robot whose plan moves it away from a person standing
// still may resume, and a hand moving sideways does not inflate S_p.
// Retreat (SsmParams::retreat_speed): a pair inside S_p whose robot sphere
// moves away from the human sphere at retreat_speed or faster does not stop
// the robot (it binds with margin 0: SLOW_DOWN, "retreating"); the planner
// predicts the same rule (safety::SsmPairRule), so that a robot in the
// person's way can get out of it.
// Verdict: PROTECTIVE_STOP when the separation is below S_p, or the bound
// reaches 1 - delta_CL within the stop horizon, or the robot state is
// unknown, or (person_required) no person is tracked; SLOW_DOWN when within
// a margin of either; OK otherwise. Without a usable prediction the monitor
// runs degraded: separation only, at the ISO default human speed. A person
// seen only as depth points (no fresh skeleton, or no usable prediction) is
// monitored on the points: risk_points.cc, point_risk.h.
//
// Several people (skeletons and predictions carry a body id): each body's
// skeleton history and newest prediction are kept apart (cell::PerBody:
// out-of-order updates refused, bodies unseen for speed_window + stale_after
// dropped). The separation is the minimum over the persons seen (each with
// its own measured speed, or the default speed when that person has no
// fresh prediction); the bound at a waypoint is the union bound over the
// persons with a fresh prediction, min(1, sum of each person's bound)
// (cell::UnionBound). The waypoints are those of the newest prediction;
// another person's prediction is taken at its step nearest to each
// waypoint's time (its first step before it, its last after it), as the
// planner does.
//
// Frames and units: positions in the world frame (= robot base frame), m;
// times are ns since the epoch on input and s relative to the evaluation in
// the report. Not thread-safe (one owner, the service's executor).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/cell/joint_trajectory.h"
#include "iplan/cell/people.h"
#include "iplan/safety/ssm.h"
#include "iplan/cell/status.h"
#include "iplan/cell/timed_prediction.h"
#include "iplan/collision/human_model.h"
#include "iplan/collision/joint_mixture.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/trajectory_bound.h"
#include "point_risk.h"

namespace iplan::collision_risk {

/// ISO/TS 15066 speed and separation monitoring parameters (iplan/cell/ssm.h).
using SsmParams = safety::SsmParams;

struct RiskParams {
  double delta_cl = 0.95;          ///< a waypoint is safe when its bound < 1 - delta_cl
  double stop_horizon = 1.0;       ///< s; a violating waypoint within it means stop, later means slow down
  double slow_down_fraction = 0.5; ///< slow down above this fraction of 1 - delta_cl
  double slow_down_margin = 0.2;   ///< m; slow down within S_p + margin
  /// Bound retreat: a trajectory that violates the bound within the stop
  /// horizon is not stopped when its largest bound there is at least this
  /// much below that of the robot held where it stands (stopping would
  /// leave it in the person's predicted way): SLOW_DOWN, "retreating".
  /// 0: off (every violation within the horizon stops).
  double bound_retreat_gain = 0.05;
  double stale_after = 0.5;        ///< s; older skeletons, predictions, robot states are ignored
  /// No fresh skeleton and no fresh depth points mean protective stop: a
  /// person no sensor sees could be anywhere. false: "no person seen" is
  /// clear (a cell whose perception publishes nothing when nobody is there).
  bool person_required = true;
  /// rad (m for prismatic joints); a robot state further outside the joint
  /// limits is refused as corrupt (encoder noise and a stop's overshoot stay within)
  double joint_limit_tolerance = 0.05;
  SsmParams ssm;
  /// The person seen only as points (/iplan/human/points): point_risk.h.
  PointsParams human_points;
  /// Empty when valid, else the reason.
  std::string Validate() const;

  /// The keys of section collision_risk (config/collision_risk.yaml), the
  /// ISO/TS 15066 ones in its iso_ts_15066 mapping; ranges: Validate().
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(delta_cl, "a waypoint is safe when its bound < 1 - delta_cl, in (0, 1)"));
    a->Visit(IPLAN_NVP(stop_horizon, "s; a violation within it stops, later slows down, >= 0"));
    a->Visit(IPLAN_NVP(slow_down_fraction, "slow down above this fraction of 1 - delta_cl, in (0, 1]"));
    a->Visit(IPLAN_NVP(slow_down_margin, "m; slow down within S_p + this, >= 0"));
    a->Visit(IPLAN_NVP(bound_retreat_gain, "a trajectory that lowers the bound within the stop horizon by this much against standing still is a retreat, not a stop (0: off), in [0, 1]"));
    a->Visit(IPLAN_NVP(stale_after, "s; older skeletons, predictions, robot states are not used, > 0"));
    a->Visit(IPLAN_NVP(person_required, "no fresh skeleton or depth points means protective stop"));
    a->Visit(IPLAN_NVP(joint_limit_tolerance, "rad; a robot state further outside the limits is refused, >= 0"));
    a->Visit(core::MakeNameValue("iso_ts_15066", &ssm, "ISO/TS 15066 speed and separation monitoring"));
    a->Visit(core::MakeNameValue("human_points", &human_points, "the person seen only as depth points"));
  }
};

using cell::Verdict;

struct RiskReport {
  int64_t stamp_ns = 0;                  ///< evaluation time
  int64_t trajectory_stamp_ns = 0;       ///< 0: no trajectory
  int64_t prediction_stamp_ns = 0;       ///< 0: no prediction used
  double time_step = 0;                  ///< s between waypoint_bounds entries
  std::vector<double> waypoint_bounds;   ///< bound per future prediction step, first at +time_step or later
  std::vector<double> waypoint_times;    ///< s after stamp_ns, per entry
  double max_bound = 0;
  int max_waypoint = 0;
  double max_time = 0;                   ///< s after stamp_ns
  std::string max_robot_link, max_human_segment, max_action;
  cell::BodyId max_body_id = 0;          ///< person of the largest share of max_bound (0: none)
  int num_people = 0;                    ///< persons with a fresh skeleton
  int num_predicted = 0;                 ///< persons with a fresh prediction (terms of the union bound)
  safety::Separation min_separation;       ///< m; nullopt when no person is seen
  std::string separation_robot_link, separation_human_segment;
  double protective_separation = 0;      ///< m, S_p of the binding pair (smallest separation - S_p)
  double human_speed = 0;                ///< m/s used for that S_p (towards the robot when directed)
  double robot_speed = 0;                ///< m/s used for that S_p (towards the person when directed)
  safety::Separation binding_separation;   ///< m, separation of the binding pair; nullopt when no person is seen
  safety::Separation separation_margin;    ///< m, binding_separation - protective_separation (0 for a retreat); < 0 stops
  /// A retreat, not a stop: the binding pair is inside S_p, its robot
  /// sphere moving away (safety::SsmPair), or the trajectory lowers the bound
  /// within the stop horizon against standing still (bound_retreat_gain).
  /// A supervisor resumes a retreat at once (no resume delay).
  bool retreating = false;
  /// Largest bound within the stop horizon along the trajectory and with the
  /// robot held where it stands; both 0 unless a prediction (or, without
  /// one, the depth camera's human points) is fresh and the trajectory
  /// moves the robot within the stop horizon.
  double horizon_bound = 0, hold_bound = 0;
  /// ISO/TS 15066 speed reduction (SsmParams::speed_reduction): the
  /// fraction of the executing trajectory's speed the robot may run at, in
  /// [0, 1]: below 1 with SLOW_DOWN (the path time-scaled), 0 with
  /// PROTECTIVE_STOP, else 1. `stop_scale` is the smallest fraction at which
  /// every pair keeps d >= S_p (below min_speed_scale: a stop); 0 where the
  /// separation does not give one (depth points: no speed reduction).
  double speed_scale = 1.0;
  double stop_scale = 0.0;
  std::string binding_robot_link, binding_human_segment;
  cell::BodyId binding_body_id = 0;      ///< person of the binding pair (0: nobody seen)
  Verdict verdict = Verdict::kProtectiveStop;
  std::string reason;
};

/// The predicted person at joint level (see iplan/collision/joint_mixture.h).
using PredictionInput = collision::JointMixture;

class RiskMonitor {
 public:
  /// Throws std::invalid_argument when params are invalid.
  RiskMonitor(collision::RobotModel robot, collision::HumanBodyParams body, RiskParams params);

  /// Each Update returns nullopt when accepted, else why it was rejected
  /// (unknown joint names, wrong sizes, a robot state outside the joint
  /// limits); rejected input leaves state alone.
  std::optional<std::string> UpdateRobotState(int64_t stamp_ns, const std::vector<std::string>& names,
                                              const std::vector<double>& positions);
  /// `times` in s from `start_ns`, increasing; positions one vector per point.
  std::optional<std::string> UpdateTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                              const std::vector<double>& times,
                                              const std::vector<std::vector<double>>& positions);
  /// One person's skeleton (refused when not after that body's previous one).
  std::optional<std::string> UpdateSkeleton(cell::BodyId body_id, int64_t stamp_ns,
                                            const std::vector<std::string>& names,
                                            const std::vector<Eigen::Vector3d>& positions);
  /// One person's prediction: replaces that body's, when its observation
  /// (t0) is newer.
  std::optional<std::string> UpdatePrediction(cell::BodyId body_id, const PredictionInput& prediction);
  /// The same for a cell of one person (body 1).
  std::optional<std::string> UpdateSkeleton(int64_t stamp_ns, const std::vector<std::string>& names,
                                            const std::vector<Eigen::Vector3d>& positions) {
    return UpdateSkeleton(1, stamp_ns, names, positions);
  }
  std::optional<std::string> UpdatePrediction(const PredictionInput& prediction) {
    return UpdatePrediction(1, prediction);
  }
  /// The points of the people the depth camera sees (risk_points.cc): means
  /// 3 x n (m, W), covariances (m^2), voxel_size (m, 0: not reduced). Fresh
  /// points stand for the person while no fresh skeleton does (separation),
  /// and for the prediction while none is usable (bound); an empty fresh set
  /// means the camera sees nobody. These points are not tracked.
  std::optional<std::string> UpdateHumanPoints(int64_t stamp_ns, double voxel_size, const Eigen::Matrix3Xd& means,
                                               const std::vector<Eigen::Matrix3d>& covariances);
  /// The same with the points' tracked velocities (point_risk.h): a point
  /// of a tracked part is judged at its measured, directed speed and moves
  /// in the bound's prediction; the others at the ISO default speed, still.
  std::optional<std::string> UpdateHumanPoints(cell::HumanPoints points);

  /// Evaluates both layers at `now_ns`. Allocates (report vectors).
  RiskReport Evaluate(int64_t now_ns);

  const collision::RobotModel& robot() const { return robot_; }
  const collision::HumanBodyModel& body() const { return body_; }
  const RiskParams& params() const { return params_; }

 private:
  /// What Evaluate knows before it looks at the layers.
  struct Inputs {
    bool person = false;     ///< a fresh skeleton
    bool predicted = false;  ///< a fresh prediction (of anyone)
    bool degraded = false;   ///< a person without a usable prediction (SsmParams::degrade_without_prediction)
    int64_t stale_ns = 0;    ///< RiskParams::stale_after
    bool points = false;     ///< fresh human points (the depth camera's view)
  };
  /// The points' layers (risk_points.cc): separation when no skeleton is
  /// fresh, the bound along the executing trajectory when no prediction is.
  void EvaluateSeparationFromPoints(int64_t now_ns, RiskReport* r);
  void EvaluateBoundFromPoints(int64_t now_ns, RiskReport* r);
  /// The ISO/TS 15066 layer into r: separation and S_p per sphere pair.
  void EvaluateSeparation(int64_t now_ns, const Inputs& in, RiskReport* r);
  /// The prediction layer into r: bound along the executing trajectory.
  void EvaluateBound(int64_t now_ns, RiskReport* r);
  /// The prediction layer's waypoints: the times of the newest prediction's
  /// steps not yet past, and that prediction's own step at each.
  struct BoundWaypoints {
    const cell::TimedPrediction* ref = nullptr;
    std::vector<int> ref_steps;
    std::vector<int64_t> times;  ///< ns since the epoch
  };
  void ForEachPersonBound(int64_t now_ns, const BoundWaypoints& w, collision::RobotSpheresTrajectory* t,
                          const std::function<void(cell::BodyId, const cell::TimedPrediction&)>& use);
  bool MovesWithinStopHorizon(int64_t now_ns, const std::vector<int64_t>& times) const;
  /// RiskReport::hold_bound and horizon_bound (the bound retreat).
  void CompareWithStandingStill(int64_t now_ns, const BoundWaypoints& w, collision::RobotSpheresTrajectory* traj,
                                RiskReport* r);
  /// Why an OK verdict is one: what the monitor saw.
  static const char* ClearReason(const Inputs& in, bool seen, bool separation);
  /// The verdict policy (see the file comment) from both layers.
  void DecideVerdict(int64_t now_ns, const Inputs& in, RiskReport* r) const;
  Eigen::VectorXd RobotConfigurationAt(int64_t t_ns) const;
  /// Skeleton history of one body (body joint order), newest last.
  using SkeletonHistory = std::deque<std::pair<int64_t, Eigen::Matrix3Xd>>;
  /// The binding and closest sphere pairs over the persons so far.
  struct SeparationSearch;
  /// One person's sphere pairs into `search`; `may_measure` false: the
  /// person is taken at the default speed (no fresh prediction, degraded).
  void SearchPerson(const SkeletonHistory& history, bool may_measure, const Eigen::Matrix3Xd& v_robot,
                    SeparationSearch* search, RiskReport* r) const;
  /// Per-joint velocity (m/s, 3 x joints) over the speed window; false when
  /// not measured (measure_human_speed off or too little history).
  bool MeasuredJointVelocities(const SkeletonHistory& history, Eigen::Matrix3Xd* v) const;
  /// Velocity (m/s, 3 x spheres) of the robot spheres along the executing
  /// trajectory, else from the last two joint states, else zero.
  void RobotSphereVelocities(int64_t now_ns, Eigen::Matrix3Xd* v);

  collision::RobotModel robot_;
  std::vector<std::string> robot_joints_;  // robot_.JointNames()
  collision::HumanBodyModel body_;
  RiskParams params_;
  collision::RobotData data_;
  collision::RobotData data2_;
  // Robot state (model joint order).
  std::optional<std::pair<int64_t, Eigen::VectorXd>> state_, previous_state_;
  // Executing trajectory (empty: none).
  cell::JointTrajectory trajectory_;
  // Skeleton history per person.
  cell::PerBody<SkeletonHistory> skeletons_;
  int64_t last_skeleton_ns_ = 0;  // newest skeleton of anyone (0: none yet), for the verdict's reason
  // Newest prediction per person (stamp: its t0), converted for the bound.
  cell::PerBody<cell::TimedPrediction> predictions_;
  collision::TrajectoryBoundWorkspace workspace_;
  std::vector<collision::WaypointBound> bounds_;
  // Latest human points and their stamp (0: none yet).
  collision::GaussianPoints points_;
  cell::HumanPoints seen_points_;  // as received (their motions; means and covariances as points_)
  int64_t points_stamp_ns_ = 0;
};

}  // namespace iplan::collision_risk
