// The replanning loop of the trajectory-optimisation service (METHOD 5,
// interleaved planning and execution), without DDS types.
//
// Every planning step m the service calls Cycle(now): the part of the
// current trajectory that executes while the new plan is computed (the first
// `frozen_waypoints`) is kept, the rest is re-optimised against the newest
// prediction from the newest state, warm-started from the previous plan.
// When no safe trajectory exists the planner inserts waits; the task's delay
// accumulates and is reported in the outcome, so the task planner learns to
// avoid tasks that make the robot wait.
//
// Units: s, rad; times are ns since the epoch. Not thread-safe (one owner);
// Cycle() blocks for the planning time.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "iplan/core/name_value.h"

#include <Eigen/Core>

#include "services/trajopt/core/escape.h"
#include "services/trajopt/core/points_prediction.h"
#include "iplan/cell/human_points.h"
#include "iplan/cell/joint_trajectory.h"
#include "iplan/cell/people.h"
#include "iplan/cell/status.h"
#include "iplan/cell/timed_prediction.h"
#include "iplan/collision/joint_mixture.h"
#include "iplan/planning/planner.h"

namespace iplan::trajopt {

struct ReplannerParams {
  double planning_step = 0.1;   ///< s, m: one cycle per step
  int frozen_waypoints = 3;     ///< executing prefix kept each cycle (>= 2)
  double goal_tolerance = 0.01; ///< rad, max joint error to count as arrived
  double settle_speed = 0.05;   ///< rad/s, max joint speed to count as arrived
  double stale_after = 0.5;     ///< s; older robot states / predictions are not used
  /// rad; when the robot is further than this from where the executing plan
  /// says it should be (e.g. after a protective stop), replan from the
  /// measured state instead of continuing the plan.
  double max_tracking_error = 0.05;
  /// rad; a robot state further outside the joint position limits is refused
  /// as corrupt (encoder noise and a stop's overshoot stay within).
  double joint_limit_tolerance = 0.05;
  /// A robot state whose joint speed exceeds this many times the joint's
  /// velocity limit is refused; above 1 for noisy measured velocities.
  double joint_velocity_factor = 1.2;
  /// s of wall time one cycle's planning may take (PlanningRequest::
  /// time_budget); 0: none. With a budget a loaded machine gets worse plans
  /// (or a wait), not late ones; the simulated-time benchmark plans without
  /// one so that it stays deterministic.
  double cycle_budget = 0.0;
  /// s; patience with a person who holds the robot off (predict_ssm): the
  /// margin a plan keeps above the separation monitor's S_p and the band in
  /// which the ssm cost pushes it back (the planner's ssm_margin and
  /// ssm_activation; PlanningRequest::ssm_scale) shrink linearly with the
  /// running task's delay (waits, holding off, time in stop), the margin to
  /// 0 once the delay reaches this, so
  /// that a person who keeps working near the goal delays the task for a
  /// while and is then approached as closely as the monitor allows (a plan
  /// the predicted monitor would stop stays infeasible). A protective stop
  /// restarts it: the delay counts from the end of the last stop, so a robot
  /// that came too close is not sent straight back at the person. 0: off
  /// (the margin is always the planner's).
  double ssm_patience = 0.0;
  /// The person seen only by the depth camera (points_prediction.h): what
  /// cycles plan against while no fresh skeleton prediction exists.
  PointsPredictionParams human_points;
  /// Getting out of the person's way when no safe plan exists (escape.h):
  /// the collision-risk monitor's stop horizon and bound retreat gain.
  EscapeParams escape;
  /// The keys of section trajopt (config/trajopt.yaml); ranges: Validate().
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(planning_step, "s; one replanning cycle per step, > 0"));
    a->Visit(IPLAN_NVP(frozen_waypoints, "executing prefix kept each cycle, >= 2"));
    a->Visit(IPLAN_NVP(goal_tolerance, "rad; max joint error to count as arrived, > 0"));
    a->Visit(IPLAN_NVP(settle_speed, "rad/s; max joint speed to count as arrived, > 0"));
    a->Visit(IPLAN_NVP(stale_after, "s; older robot states and predictions are not used, > 0"));
    a->Visit(IPLAN_NVP(max_tracking_error, "rad; further from the plan: replan from the measured state, > 0"));
    a->Visit(IPLAN_NVP(joint_limit_tolerance, "rad; a state further outside the limits is refused, >= 0"));
    a->Visit(IPLAN_NVP(joint_velocity_factor, "a state faster than this x the velocity limit is refused, >= 1"));
    a->Visit(IPLAN_NVP(cycle_budget, "s of wall time one cycle's planning may take, [0, planning_step); 0: none"));
    a->Visit(IPLAN_NVP(ssm_patience, "s of a task's delay (since its last protective stop) after which its plans keep no margin above S_p, >= 0; 0: off"));
    a->Visit(IPLAN_NVP(human_points, "the depth camera's human points as a constant-velocity prediction, planned against while no skeleton prediction is fresh"));
  }
  std::string Validate() const;
};

using cell::TaskStatus;

struct TaskSpec {
  uint32_t id = 0;
  std::string name;
  planning::Goal goal;
  double time_limit = 0;  ///< s; 0: none
  /// Joint positions (rad, model order) the robot withdraws to after
  /// reaching `goal`, e.g. out of the person's space after a hand-over; the
  /// task ends there, so the delay of withdrawing is the task's own. Empty:
  /// the task ends at the goal.
  Eigen::VectorXd retreat = Eigen::VectorXd();
};

struct TaskOutcome {
  uint32_t id = 0;
  std::string name;
  TaskStatus status = TaskStatus::kFailed;
  std::string reason;
  double duration = 0;       ///< s, command to arrival at the goal, or at the retreat when there is one (or to the end)
  double delay = 0;          ///< s from each cycle whose plan waited or was held off by the person's
                             ///< keep-out, or during which the robot was in protective stop, to the
                             ///< next cycle (wall time)
  uint32_t num_waits = 0;    ///< cycles whose plan had to insert a wait
  double planning_time_p50 = 0, planning_time_p99 = 0;  ///< s per cycle
  double max_collision_bound = 0;
};

struct CycleResult {
  bool publish = false;              ///< a trajectory to publish
  int64_t start_ns = 0;              ///< time of waypoint 0
  double dt = 0;
  Eigen::MatrixXd positions;         ///< nq x (n + 1)
  double planning_time = 0;          ///< s, 0 when nothing was planned
  int64_t prediction_t0_ns = 0;      ///< stamp of the observation behind the newest prediction planned against (0: none)
  int num_people = 0;                ///< persons planned against (fresh predictions)
  bool waiting = false;              ///< the plan holds the robot (waits inserted or no safe trajectory)
  bool held_off = false;             ///< the plan keeps out of the person's space (human_separation, predict_ssm) or, idle, yields to them
  double max_bound = 0;              ///< highest per-waypoint collision bound of the plan
  bool budget_exhausted = false;     ///< planning ran out of ReplannerParams::cycle_budget
  std::optional<TaskOutcome> outcome;
  std::string status;                ///< what happened, for logs/diagnostics
};

class Replanner {
 public:
  /// `planner` must outlive this object. Throws std::invalid_argument on bad params.
  Replanner(const planning::Planner& planner, const collision::HumanBodyModel& body, ReplannerParams params);

  /// A new task replaces the current one, whose outcome (CANCELLED) is
  /// returned. A repeat of the running task's id is ignored (commands may be
  /// re-sent after a fault). Throws std::invalid_argument when a retreat
  /// does not have one position per robot joint.
  std::optional<TaskOutcome> StartTask(const TaskSpec& task, int64_t now_ns);
  /// Cancels the current task if it has this id.
  std::optional<TaskOutcome> CancelTask(uint32_t id, int64_t now_ns);
  bool busy() const { return task_.has_value(); }
  /// The robot is in (or left) protective stop: time stopped counts as the
  /// running task's delay, like waiting.
  void SetRobotStopped(bool stopped) { robot_stopped_ = stopped; }
  std::optional<uint32_t> current_task_id() const { return task_ ? std::optional<uint32_t>(task_->spec.id) : std::nullopt; }

  /// Newest robot state. Returns why it was refused (a joint missing, a
  /// position or velocity outside the limits by more than the tolerance).
  std::optional<std::string> UpdateRobotState(int64_t stamp_ns, const std::vector<std::string>& names,
                                              const std::vector<double>& q, const std::vector<double>& qd);
  /// Newest prediction of one person (body id): replaces that body's when
  /// its observation is newer. Returns why it was refused. Every cycle plans
  /// against each person whose prediction is fresh (stale_after); older
  /// ones are dropped.
  std::optional<std::string> UpdatePrediction(cell::BodyId body_id, const collision::JointMixture& prediction);
  /// The same for a cell of one person (body 1).
  std::optional<std::string> UpdatePrediction(const collision::JointMixture& prediction) {
    return UpdatePrediction(1, prediction);
  }
  /// The people the depth camera sees (the cloud service's points and their
  /// tracked velocities): while no fresh skeleton prediction exists, cycles
  /// plan against their constant-velocity prediction (points_prediction.h),
  /// fresh for stale_after from the cloud's stamp; an empty set means
  /// nobody is seen. Returns why the points were refused (seen.Check()).
  std::optional<std::string> UpdateHumanPoints(const cell::HumanPoints& seen);
  /// True when a cycle at now_ns would plan against the depth camera's
  /// points (fresh points, no fresh skeleton prediction).
  bool PlansOnPoints(int64_t now_ns) const;

  /// The perceived obstacles (W) every later cycle keeps clear of
  /// (PlanningRequest::obstacles; see obstacle_set.h).
  void SetObstacles(std::vector<collision::SceneObject> obstacles) { obstacles_ = std::move(obstacles); }

  /// One planning step at `now_ns`.
  CycleResult Cycle(int64_t now_ns);

  /// The robot's joints in q order (what trajectories carry).
  const std::vector<std::string>& joint_names() const { return robot_joints_; }

 private:
  TaskOutcome Finish(TaskStatus status, const std::string& reason, int64_t now_ns);
  CycleResult Hold(int64_t now_ns, const Eigen::VectorXd& q, const std::string& status);
  std::optional<CycleResult> CheckProgress(int64_t now_ns, CycleResult* r);
  planning::PlanningRequest MakeRequest(int64_t now_ns, const planning::Goal& goal, int64_t* start_ns, CycleResult* r);
  CycleResult StandBy(int64_t now_ns);
  bool StandsStill(int64_t now_ns) const;
  std::optional<planning::Goal> AsideGoal(const planning::PlanningRequest& req) const;
  /// When the robot held where it stands would reach the bound within the
  /// monitor's stop horizon: the escape plan (escape.h), else nullopt.
  std::optional<planning::PlanningResult> Escape(const planning::PlanningRequest& req,
                                                 const planning::PlanningResult& failed) const;
  std::optional<double> UnsafeHoldBound(const planning::PlanningRequest& req) const;
  void ApplyPlan(const planning::PlanningRequest& req, const planning::PlanningResult& res, CycleResult* r);
  static std::pair<int64_t, double> PathLag(const cell::JointTrajectory& plan, int64_t stamp_ns, const Eigen::VectorXd& q,
                                            int64_t max_lag_ns);

  const planning::Planner& planner_;
  const collision::HumanBodyModel& body_;
  ReplannerParams params_;
  std::optional<std::pair<int64_t, Eigen::VectorXd>> q_;
  Eigen::VectorXd qd_;
  bool robot_stopped_ = false;
  std::vector<std::string> robot_joints_;
  cell::PerBody<cell::TimedPrediction> predictions_;  // newest per person, stamp: its observation
  // The depth camera's points as a prediction (none: nobody seen), and the cloud's stamp.
  std::optional<collision::HumanPrediction> points_prediction_;
  int64_t points_stamp_ns_ = 0;
  std::vector<collision::SceneObject> obstacles_;
  struct Active {
    TaskSpec spec;
    int64_t start_ns = 0;
    std::optional<Eigen::VectorXd> goal_q;  // where the robot is going now (the retreat once the goal is reached)
    bool retreating = false;                // the goal is reached; withdrawing to spec.retreat
    double delay = 0;
    double patience_from = 0;    // delay at the end of the last protective stop (patience counts from there)
    uint32_t waits = 0;
    double max_bound = 0;
    std::vector<double> planning_times;
    bool waiting = false;        // the last cycle's plan made the robot wait
    bool stopped = false;        // the robot was in protective stop at the last cycle
    int64_t last_cycle_ns = 0;
  };
  std::optional<Active> task_;
  // Where the robot was left without a task (it returns there after yielding).
  std::optional<Eigen::VectorXd> park_;
  // The running cycle's bound of standing still, when it reaches 1 - delta_CL
  // (UnsafeHoldBound of MakeRequest's request; nullopt: safe, or no escaping).
  std::optional<double> unsafe_hold_;
  // Wall time the running cycle started (its budget: ReplannerParams::cycle_budget).
  std::chrono::steady_clock::time_point cycle_start_;
  // Previous plan (the trajectory being executed).
  std::optional<std::pair<int64_t, Eigen::MatrixXd>> previous_;
};

}  // namespace iplan::trajopt
