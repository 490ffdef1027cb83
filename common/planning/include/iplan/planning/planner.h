// ITOMP-style trajectory optimisation (METHOD.md section 5): space-time
// waypoints, smoothness + static clearance + probabilistic dynamic cost +
// goal, N parallel seeded optimisers, waits when no safe trajectory exists,
// and a warm-start entry point for a replanning loop.
//
// Trajectory: waypoints q_0 .. q_n (columns of an nq x (n+1) matrix, rad) at
// t_i = i dt (relative to waypoint 0). Discrete derivatives used everywhere
// (optimiser, feasibility check, tests) are iplan/cell/joint_trajectory.h's
// FiniteDifference*:
//   v_i = (q_{i+1} - q_i) / dt,                  i = 0 .. n-1
//   a_i = (q_{i+1} - 2 q_i + q_{i-1}) / dt^2,     i = 0 .. n,
// with the virtual waypoints q_{-1} = q_0 - qdot_0 dt (start velocity) and
// q_{n+1} = q_n (the robot stops at the goal). q_0 is the start, q_n the goal
// configuration; the first `num_frozen` waypoints are never changed.
//
// Costs (weights in PlannerParams::weights):
//   smoothness  sum_i dt ||a_i||^2
//   obstacle    sum_i sum_(sphere, object) max(0, margin - d)^2, d the signed
//               distance of a robot sphere to a scene object (m)
//   dynamic     sum_i max(0, P_i - tau)^2, P_i the bound of
//               collision::EvaluateTrajectoryBound at waypoint i and
//               tau = dynamic_activation (1 - delta_CL)
//   goal        sum_i dt ||q_i - q_goal||^2 (reach the goal early)
//   limits      squared excess of |v|, |a| over limit_scale x limit, normalised
// Positions are kept inside the limits by projection after every step.
//
// Prediction timing, per person: waypoint i (time t_i) uses step
//   s_i = clamp(round((t_i - start) / dt), 0, S - 1)
// of that person's prediction (PersonPrediction), i.e. the step nearest to
// t_i. Waypoints before the prediction's first step use step 0, waypoints
// beyond its last step use the last step (the person is assumed to stay
// where last predicted, rather than to vanish).
//
// Several people: P_i is the union bound over them, min(1, sum over persons
// of each person's bound) (cell::UnionBound); the keep-out cost adds up over
// persons and human_separation is the nearest person's. With one person
// everything is as for that person alone.
//
// The pieces (problem, cost terms, optimiser, multi-start, waits) are
// internal: common/planning/src/planner_model.h maps them to their files.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/collision/trajectory_bound.h"
#include "iplan/planning/kinematics.h"
#include "iplan/planning/planner_params.h"

namespace iplan::planning {

/// A goal: a joint configuration, or a pose of the end effector
/// (PlannerParams::end_effector_link/offset) in W.
struct Goal {
  enum class Kind { kJoint, kPose };
  Kind kind = Kind::kJoint;
  Eigen::VectorXd q;                                            ///< kJoint: size nq (rad)
  Eigen::Vector3d p_WE = Eigen::Vector3d::Zero();               ///< kPose: position (m, W)
  Eigen::Quaterniond R_WE = Eigen::Quaterniond::Identity();     ///< kPose: orientation (W)

  static Goal Joint(Eigen::VectorXd q);
  static Goal Pose(const Eigen::Vector3d& p_WE, const Eigen::Quaterniond& R_WE);
};

/// One person's prediction for a plan.
struct PersonPrediction {
  /// Not owned, not null; its summaries must be up to date
  /// (HumanPrediction::UpdateSummaries).
  const collision::HumanPrediction* spheres = nullptr;
  double time_step = 0.1;  ///< time between prediction steps (s), > 0
  double start = 0.0;      ///< time of step 0 minus time of waypoint 0 (s)
};

struct PlanningRequest {
  Eigen::VectorXd start_q;     ///< size nq (rad), within limits
  Eigen::VectorXd start_qdot;  ///< size nq (rad/s), or empty = at rest
  Goal goal;
  /// Optional initial trajectory (nq x m, at the planner's dt, column 0 =
  /// start_q): the warm start of a replanning cycle (see ShiftTrajectory).
  /// Optimiser 0 starts from it; the others from perturbations of it.
  Eigen::MatrixXd warm_start;
  /// Number of leading waypoints that are frozen (>= 1; waypoint 0 is the
  /// start). Waypoints 1 .. num_frozen-1 are taken from warm_start, which
  /// must then have at least num_frozen columns.
  int num_frozen = 1;
  /// The predicted people (empty: nobody), one entry per person.
  std::vector<PersonPrediction> people;
  /// Wall time Plan may take (s); 0: no limit. With a budget the planner is
  /// anytime: when it runs out, the optimisers stop at their next iteration,
  /// no further wait is inserted, and the best feasible and safe trajectory
  /// found so far wins; without one the status is kNoSafeTrajectory or
  /// kInfeasible (a replanner then holds: a wait). PlanningResult::
  /// budget_exhausted tells. Results then depend on timing; without a budget
  /// they are bit-identical for the same request, parameters and seed.
  double time_budget = 0.0;
  /// Obstacles perceived at run time (W, m; e.g. the boxes of
  /// /iplan/obstacles) that join the scene for this request: every robot
  /// sphere is kept clear of them like of the scene's objects (obstacle cost,
  /// clearance check, goal check). Each must pass SceneParams::Validate.
  std::vector<collision::SceneObject> obstacles;
  /// The fraction of PlannerParams::ssm_margin and ssm_activation that this
  /// request's plans keep above the separation monitor's S_p (predict_ssm),
  /// in [0, 1]; the cost's band above the margin keeps at least 0.02 m. A
  /// replanner lowers it while a task is held off (ReplannerParams::
  /// ssm_patience), so that a person who stays near the goal delays the
  /// robot for a while, not for ever; at 0 a plan may come as close as the
  /// predicted monitor allows, never closer.
  double ssm_scale = 1.0;
  /// Waits this request may insert before giving up; -1: PlannerParams::
  /// max_waits. 0 for a plan that must move now (an escape: a wait would
  /// leave the robot where it is).
  int max_waits = -1;
};

enum class PlanStatus {
  kSuccess,             ///< feasible and safe, no wait needed
  kSuccessAfterWait,    ///< feasible and safe after num_waits waits
  kNoSafeTrajectory,    ///< every attempt violated the bound (max_waits reached)
  kInfeasible,          ///< no attempt satisfied limits / static clearance
  kIkFailed,            ///< the goal pose has no IK solution within tolerance
  kGoalInCollision,     ///< the goal configuration is inside a scene object
};
const char* ToString(PlanStatus status);

struct PlanningResult {
  PlanStatus status = PlanStatus::kInfeasible;
  /// Feasible and safe (kSuccess or kSuccessAfterWait).
  bool success() const { return status == PlanStatus::kSuccess || status == PlanStatus::kSuccessAfterWait; }
  std::string reason;            ///< human-readable explanation when !success()
  double dt = 0.0;               ///< s
  /// nq x (n+1) waypoints (rad): the winner, or on failure the best attempt
  /// (lowest cost; may violate constraints, see `reason`). Empty on IK failure.
  Eigen::MatrixXd positions;
  Eigen::VectorXd goal_q;        ///< goal configuration used (rad)
  int num_frozen = 1;            ///< frozen prefix incl. inserted waits
  double delay = 0.0;            ///< total inserted wait time (s)
  int num_waits = 0;
  double planning_time = 0.0;    ///< wall time of Plan (s)
  bool budget_exhausted = false; ///< PlanningRequest::time_budget ran out before the optimisers finished
  double time_to_first_feasible = -1.0;  ///< wall time until some optimiser was feasible (s), -1 if never
  double max_bound = 0.0;        ///< max_i P_i over the non-frozen waypoints (0 without people)
  std::vector<double> bounds;    ///< P_i per waypoint (empty without people)
  double cost = 0.0;             ///< final total cost
  double min_clearance = 0.0;    ///< m, at the interpolated check points
  /// m, smallest distance of the free waypoints to the predicted person
  /// (as the human_separation cost measures it; +inf without prediction).
  double human_separation = std::numeric_limits<double>::infinity();
  /// m, smallest d - S_p of the separation monitor's rule over the judged
  /// waypoints, retreats left out (PlannerParams::predict_ssm; +inf when
  /// off, without people or with no pair within ssm_activation).
  double ssm_margin = std::numeric_limits<double>::infinity();
  int winning_optimizer = -1;
  int num_feasible = 0;          ///< optimisers feasible and safe in the last attempt
};

/// The planner: immutable robot model, scene and parameters. Plan() is const
/// and thread-safe; it allocates (per-optimiser workspaces) and starts up to
/// num_threads std::threads. The result is bit-identical for the same
/// request, parameters and seed, whatever the thread count.
class Planner {
 public:
  /// @throws std::invalid_argument if params are invalid or name an unknown
  ///         end-effector link / allowed-collision link or object.
  Planner(collision::RobotModel robot, collision::SceneParams scene, PlannerParams params);
  ~Planner();
  Planner(const Planner&) = delete;
  Planner& operator=(const Planner&) = delete;

  const collision::RobotModel& robot() const;
  const PlannerParams& params() const;

  /// Plans. Bad input (sizes, NaN, start or goal outside the limits, bad
  /// prediction timing or frozen prefix) throws std::invalid_argument naming
  /// the values; outcomes (unsafe, infeasible, IK failure) are statuses.
  PlanningResult Plan(const PlanningRequest& request) const;
  /// Same with other optimiser settings (num_optimizers, num_threads, seed):
  /// used by benchmarks and the CLI. Other fields of `params` are ignored.
  PlanningResult Plan(const PlanningRequest& request, int num_optimizers, int num_threads,
                      std::uint64_t seed) const;

  /// IK for an end-effector pose (PlannerParams end effector and IK options),
  /// seeded at q_seed, restarts drawn from a generator seeded with `seed`.
  IkResult SolveIk(const Eigen::Vector3d& p_WE, const Eigen::Quaterniond& R_WE,
                   const Eigen::VectorXd& q_seed, std::uint64_t seed) const;
  /// The same for a tool that may turn about its own axis: the end effector
  /// at p_WE (m, world frame) with its link's z axis along z_W (unit, world
  /// frame; orientation_error is the angle between them). `restarts` >= 0
  /// replaces PlannerParams::ik_restarts (0: from q_seed only).
  IkResult SolveIkForToolAxis(const Eigen::Vector3d& p_WE, const Eigen::Vector3d& z_W,
                              const Eigen::VectorXd& q_seed, std::uint64_t seed, int restarts = -1) const;

  /// Minimum signed distance (m) between the robot spheres at q and the scene,
  /// skipping allowed collisions (analytic box/cylinder distances, the same
  /// as the optimiser uses). Thread-safe; allocates.
  double CalcClearance(const Eigen::VectorXd& q) const;
  /// The same including perceived `obstacles` (PlanningRequest::obstacles).
  double CalcClearance(const Eigen::VectorXd& q, const std::vector<collision::SceneObject>& obstacles) const;

  /// Sphere indices that are checked against object `object` (allowed
  /// collisions removed). For independent verification (e.g. with FCL).
  std::vector<int> CheckedSpheres(int object) const;

  /// Warm start for a replanning cycle: `previous` (nq x m at step dt)
  /// shifted by `elapsed` (s, >= 0; rounded to whole steps): column i of the
  /// result is column i + round(elapsed/dt) of previous, the last column
  /// repeated past the end, keeping m columns. Allocates.
  static Eigen::MatrixXd ShiftTrajectory(const Eigen::MatrixXd& previous, double dt,
                                         double elapsed);

 private:
  bool ResolveGoal(const PlanningRequest& req, std::uint64_t seed, Eigen::VectorXd* q_goal,
                   PlanningResult* result) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// PlannerParams' defaults name the Panda's links (end_effector_link
/// panda_link8 and its base pairs allowed on the table). For a robot that
/// lacks them: end_effector_link becomes its tool_link (a URDF overlay's),
/// else its last link (the URDF's last in tree order, e.g. the UR5e's
/// tool0), with offset 0; and
/// allowed_collisions its first two links with spheres against "table".
/// Parameters whose links the robot has are returned unchanged. For tools
/// and benchmarks that plan without a robot-specific config; a config that
/// names links stays checked by the Planner. Allocates.
PlannerParams AdaptLinksToRobot(PlannerParams params, const collision::RobotModel& robot);

/// Checks a trajectory against the limits of `robot` with the discrete
/// derivatives above (start velocity qdot0, size nq or empty = 0), relative
/// tolerance `tol`. Returns an empty string when it respects them, else the
/// first violation (waypoint, joint, value, limit). Thread-safe.
std::string CheckLimits(const collision::RobotModel& robot, const Eigen::MatrixXd& positions,
                        double dt, const Eigen::VectorXd& qdot0, double tol = 1e-9);

}  // namespace iplan::planning
