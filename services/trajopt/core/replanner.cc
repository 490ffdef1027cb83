#include "replanner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "iplan/core/stats.h"

namespace iplan::trajopt {
namespace {

// A robot behind the plan's timing counts as slowed down on its path (and the
// plan is re-timed) only while it moves along the path at this fraction of
// the plan's speed or more (half the monitor's smallest speed scale).
constexpr double kMinPathSpeedFraction = 0.05;

}  // namespace

std::string ReplannerParams::Validate() const {
  if (!(planning_step > 0)) return "planning_step must be > 0";
  if (frozen_waypoints < 2) return "frozen_waypoints must be >= 2";
  if (!(goal_tolerance > 0)) return "goal_tolerance must be > 0";
  if (!(settle_speed > 0)) return "settle_speed must be > 0";
  if (!(stale_after > 0)) return "stale_after must be > 0";
  if (!(max_tracking_error > 0)) return "max_tracking_error must be > 0";
  if (!(joint_limit_tolerance >= 0)) return "joint_limit_tolerance must be >= 0";
  if (!(joint_velocity_factor >= 1)) return "joint_velocity_factor must be >= 1";
  if (!(cycle_budget >= 0) || !(cycle_budget < planning_step))
    return "cycle_budget must be in [0, planning_step)";
  if (!(ssm_patience >= 0) || !std::isfinite(ssm_patience)) return "ssm_patience must be >= 0";
  return human_points.Validate();
}

Replanner::Replanner(const planning::Planner& planner, const collision::HumanBodyModel& body, ReplannerParams params)
    : planner_(planner), body_(body), params_(params), robot_joints_(planner.robot().JointNames()) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
}

std::optional<std::string> Replanner::UpdateRobotState(int64_t stamp_ns, const std::vector<std::string>& names,
                                                       const std::vector<double>& q, const std::vector<double>& qd) {
  if (names.size() != q.size()) return std::string("names and positions differ in size");
  std::vector<int> idx;
  if (auto e = cell::MapJointNames(names, robot_joints_, &idx)) return "joint state: " + *e;
  const Eigen::Index nq = static_cast<Eigen::Index>(robot_joints_.size());
  Eigen::VectorXd qq(nq), vv = Eigen::VectorXd::Zero(nq);
  for (Eigen::Index m = 0; m < nq; ++m) {
    const std::size_t i = static_cast<std::size_t>(idx[static_cast<std::size_t>(m)]);
    qq[m] = q[i];
    if (qd.size() == q.size()) vv[m] = qd[i];
  }
  // A state the arm cannot be in is a wrong or corrupted measurement;
  // planning from it would start every plan from a jump. Refused (and
  // counted), the last good state ages out and no plan is published.
  const collision::RobotModel& robot = planner_.robot();
  if (auto e = collision::CheckJointPositions(robot, qq, params_.joint_limit_tolerance)) return "joint state: " + *e;
  if (auto e = collision::CheckJointVelocities(robot, vv, params_.joint_velocity_factor)) return "joint state: " + *e;
  q_ = std::make_pair(stamp_ns, qq);
  qd_ = vv;
  return std::nullopt;
}

std::optional<std::string> Replanner::UpdatePrediction(cell::BodyId body_id, const collision::JointMixture& in) {
  return cell::KeepNewestPrediction(body_, body_id, in, params_.stale_after, &predictions_);
}

std::optional<std::string> Replanner::UpdateHumanPoints(const cell::HumanPoints& seen) {
  if (auto why = seen.Check()) return "human points: " + *why;
  if (seen.stamp_ns < points_stamp_ns_) return std::string("human points: older than the last ones");
  points_prediction_ = BuildPointsPrediction(params_.human_points, seen, planner_.params().ssm);
  points_stamp_ns_ = seen.stamp_ns;
  return std::nullopt;
}

bool Replanner::PlansOnPoints(int64_t now_ns) const {
  const int64_t stale = static_cast<int64_t>(params_.stale_after * 1e9);
  return points_prediction_ && now_ns - points_stamp_ns_ <= stale && predictions_.CountFresh(now_ns, stale) == 0;
}

TaskOutcome Replanner::Finish(TaskStatus status, const std::string& reason, int64_t now_ns) {
  if (task_->waiting || task_->stopped) task_->delay += (now_ns - task_->last_cycle_ns) * 1e-9;
  TaskOutcome o;
  o.id = task_->spec.id;
  o.name = task_->spec.name;
  o.status = status;
  o.reason = reason;
  o.duration = (now_ns - task_->start_ns) * 1e-9;
  o.delay = task_->delay;
  o.num_waits = task_->waits;
  const core::Summary s = core::Summarize(task_->planning_times);
  o.planning_time_p50 = s.p50;
  o.planning_time_p99 = s.p99;
  o.max_collision_bound = task_->max_bound;
  task_.reset();
  previous_.reset();
  park_ = q_ ? std::optional<Eigen::VectorXd>(q_->second) : std::nullopt;
  return o;
}

std::optional<TaskOutcome> Replanner::StartTask(const TaskSpec& task, int64_t now_ns) {
  std::optional<TaskOutcome> replaced;
  if (task_ && task_->spec.id == task.id) return replaced;  // a repeat of the running task
  if (task.retreat.size() != 0 && task.retreat.size() != planner_.robot().nq) {
    throw std::invalid_argument("retreat has " + std::to_string(task.retreat.size()) + " joint positions, the robot " +
                                std::to_string(planner_.robot().nq));
  }
  // Everything is checked before the running task is replaced: a command
  // that cannot be carried out must not cancel one that can.
  const Eigen::VectorXd lo = planner_.robot().LowerLimits(), hi = planner_.robot().UpperLimits();
  auto check_limits = [&](const Eigen::VectorXd& q, const char* what) {
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      if (!(q[i] >= lo[i] && q[i] <= hi[i])) {
        throw std::invalid_argument(std::string(what) + " joint " + std::to_string(i) + " at " + std::to_string(q[i]) +
                                    " rad is outside its limits [" + std::to_string(lo[i]) + ", " +
                                    std::to_string(hi[i]) + "]");
      }
    }
  };
  if (task.goal.kind == planning::Goal::Kind::kJoint) {
    if (task.goal.q.size() != planner_.robot().nq) {
      throw std::invalid_argument("goal has " + std::to_string(task.goal.q.size()) + " joint positions, the robot " +
                                  std::to_string(planner_.robot().nq));
    }
    check_limits(task.goal.q, "goal");
  } else if (!task.goal.p_WE.allFinite() || !task.goal.R_WE.coeffs().allFinite() ||
             std::abs(task.goal.R_WE.norm() - 1) > 1e-6) {
    throw std::invalid_argument("goal pose is not finite or its orientation is not a unit quaternion");
  }
  if (task.retreat.size() != 0) check_limits(task.retreat, "retreat");
  if (task_) replaced = Finish(TaskStatus::kCancelled, "replaced by task " + std::to_string(task.id), now_ns);
  // A robot at rest under a standby plan that only holds it there (kept
  // while a person is predicted near) starts the task from its state: kept,
  // that plan's frozen prefix would hold it (frozen_waypoints - 1) planning
  // steps longer. A standby plan that moves the arm (yielding) is kept.
  if (previous_ && StandsStill(now_ns)) previous_.reset();
  task_ = Active{};
  task_->spec = task;
  task_->start_ns = now_ns;
  task_->last_cycle_ns = now_ns;
  return replaced;
}

std::optional<TaskOutcome> Replanner::CancelTask(uint32_t id, int64_t now_ns) {
  if (!task_ || task_->spec.id != id) return std::nullopt;
  return Finish(TaskStatus::kCancelled, "cancelled by command", now_ns);
}

CycleResult Replanner::Hold(int64_t now_ns, const Eigen::VectorXd& q, const std::string& status) {
  CycleResult r;
  r.publish = true;
  r.start_ns = now_ns;
  r.dt = planner_.params().dt;
  r.positions = q.replicate(1, 2);
  r.status = status;
  return r;
}

CycleResult Replanner::Cycle(int64_t now_ns) {
  cycle_start_ = std::chrono::steady_clock::now();
  CycleResult r;
  const int64_t stale = static_cast<int64_t>(params_.stale_after * 1e9);
  if (!q_ || now_ns - q_->first > stale) {
    r.status = "waiting for a current robot state";
    return r;
  }
  if (!task_) return StandBy(now_ns);
  Active& t = *task_;
  // The robot waited from the previous cycle until now (cycles can be longer
  // than the planning step while the planner inserts waits).
  if (t.waiting || t.stopped) t.delay += (now_ns - t.last_cycle_ns) * 1e-9;
  t.waiting = false;
  t.stopped = robot_stopped_;
  if (t.stopped) t.patience_from = t.delay;  // a protective stop restarts patience
  t.last_cycle_ns = now_ns;
  if (std::optional<CycleResult> over = CheckProgress(now_ns, &r)) return *over;

  int64_t start_ns = now_ns;
  const planning::PlanningRequest req =
      MakeRequest(now_ns, t.goal_q ? planning::Goal::Joint(*t.goal_q) : t.spec.goal, &start_ns, &r);
  planning::PlanningResult res;
  try {
    res = planner_.Plan(req);
  } catch (const std::exception& e) {
    CycleResult bad = Hold(now_ns, q_->second, "planning refused the request");
    bad.outcome = Finish(TaskStatus::kFailed, e.what(), now_ns);
    return bad;
  }
  t.planning_times.push_back(res.planning_time);
  r.planning_time = res.planning_time;
  r.budget_exhausted = res.budget_exhausted;
  if (res.status == planning::PlanStatus::kIkFailed || res.status == planning::PlanStatus::kGoalInCollision) {
    CycleResult bad = Hold(now_ns, q_->second, "goal unreachable");
    bad.outcome = Finish(TaskStatus::kFailed, res.reason, now_ns);
    return bad;
  }
  if (!t.goal_q && res.goal_q.size() > 0) t.goal_q = res.goal_q;
  r.publish = true;
  r.start_ns = start_ns;
  r.dt = planner_.params().dt;
  ApplyPlan(req, res, &r);
  previous_ = std::make_pair(start_ns, r.positions);
  return r;
}

// True when the robot is at rest and the executing plan keeps it where it is
// over the prefix a cycle at now_ns would freeze.
bool Replanner::StandsStill(int64_t now_ns) const {
  constexpr double kStill = 1e-4;  // rad
  if (!q_ || !previous_ || qd_.cwiseAbs().maxCoeff() >= params_.settle_speed) return false;
  const double dt = planner_.params().dt;
  const cell::JointTrajectory plan = cell::JointTrajectory::Uniform(previous_->first, dt, previous_->second);
  for (int k = 0; k < params_.frozen_waypoints; ++k) {
    const int64_t t = now_ns + static_cast<int64_t>(std::llround(k * dt * 1e9));
    if ((plan.PositionAt(t) - q_->second).cwiseAbs().maxCoeff() > kStill) return false;
  }
  return true;
}

// Without a task the robot stays where it was left (the park pose), unless
// the person is predicted to come where it stands: with predict_ssm the
// planner plans to the park pose against the prediction, which moves the
// arm out of the person's way (the monitor's retreat rule) and back once
// they have gone. Without predict_ssm or a fresh prediction: a hold.
CycleResult Replanner::StandBy(int64_t now_ns) {
  if (!park_) park_ = q_->second;
  const int64_t stale = static_cast<int64_t>(params_.stale_after * 1e9);
  predictions_.Expire(now_ns, stale);
  if (!planner_.params().predict_ssm || (predictions_.CountFresh(now_ns, stale) == 0 && !PlansOnPoints(now_ns))) {
    previous_.reset();
    park_ = q_->second;
    return Hold(now_ns, q_->second, "idle");
  }
  CycleResult r;
  int64_t start_ns = now_ns;
  planning::PlanningRequest req = MakeRequest(now_ns, planning::Goal::Joint(*park_), &start_ns, &r);
  planning::PlanningResult res;
  try {
    res = planner_.Plan(req);
    // The park pose itself is where the person is going: make way to a
    // pose beside it instead (the plan's goal cannot be unsafe).
    if (!res.success()) {
      if (const std::optional<planning::Goal> aside = AsideGoal(req)) {
        req.goal = *aside;
        planning::PlanningResult other = planner_.Plan(req);
        if (other.success()) {
          res = std::move(other);
          r.status = "stepping aside; ";
        }
      }
    }
  } catch (const std::exception& e) {
    previous_.reset();
    return Hold(now_ns, q_->second, std::string("idle (planning refused the request: ") + e.what() + ")");
  }
  r.planning_time = res.planning_time;
  r.budget_exhausted = res.budget_exhausted;
  r.publish = true;
  r.start_ns = start_ns;
  r.dt = planner_.params().dt;
  if (res.success()) {
    r.positions = res.positions;
    r.max_bound = res.max_bound;
    const double away = (res.positions.colwise() - *park_).cwiseAbs().maxCoeff();
    r.held_off = away > params_.goal_tolerance;
    r.status += !r.held_off                ? "idle"
                : std::isfinite(res.ssm_margin) ? "idle, yielding to the person (predicted margin " +
                                                     std::to_string(res.ssm_margin) + " m)"
                                                : "idle, returning to where it was left";
  } else if (std::optional<planning::PlanningResult> escape = Escape(req, res)) {
    r.positions = escape->positions;
    r.max_bound = escape->max_bound;
    r.held_off = true;
    r.status += "idle, escaping the person's predicted way (bound " + std::to_string(escape->max_bound) +
                "; no safe trajectory: " + res.reason + ")";
  } else {
    const Eigen::MatrixXd& base = previous_ ? req.warm_start : q_->second.replicate(1, 1);
    const int keep = std::max(1, std::min<int>(req.num_frozen, static_cast<int>(base.cols())));
    r.positions.resize(base.rows(), keep + 1);
    r.positions.leftCols(keep) = base.leftCols(keep);
    r.positions.col(keep) = base.col(keep - 1);
    r.waiting = true;
    r.status += "idle, no safe trajectory: holding (" + res.reason + ")";
  }
  previous_ = std::make_pair(start_ns, r.positions);
  return r;
}

// The end effector moved kAsideDistance horizontally away from the person's
// predicted sphere nearest to it (the newest step of every action of every
// fresh prediction), its orientation kept; nullopt without a person or a
// direction.
std::optional<planning::Goal> Replanner::AsideGoal(const planning::PlanningRequest& req) const {
  constexpr double kAsideDistance = 0.25;  // m
  const Eigen::VectorXd q = req.warm_start.cols() > 0 ? Eigen::VectorXd(req.warm_start.col(0)) : req.start_q;
  const std::optional<AwayFromPerson> e = FindAwayFromPerson(planner_, req, q, true);
  if (!e || e->away.norm() < 1e-6) return std::nullopt;
  return planning::Goal::Pose(e->p_WE + kAsideDistance * e->away.normalized(), e->R_WE);
}

// Escaping (escape.h): only when standing still is itself unsafe, as the
// monitor judges it (its stop horizon and bound retreat gain).
std::optional<planning::PlanningResult> Replanner::Escape(const planning::PlanningRequest& req,
                                                          const planning::PlanningResult& failed) const {
  const EscapeParams& e = params_.escape;
  const std::optional<double>& hold = unsafe_hold_;  // of this cycle's request (MakeRequest)
  if (!hold) return std::nullopt;
  // What the cycle's budget leaves (the plans before spent the rest).
  double budget = 0.0;
  if (params_.cycle_budget > 0) {
    budget = params_.cycle_budget - std::chrono::duration<double>(std::chrono::steady_clock::now() - cycle_start_).count();
    if (budget <= 0) return std::nullopt;
  }
  return FindEscape(planner_, req, failed, q_->second, *hold, e, budget);
}

// The bound of standing still within the escape horizon, when it reaches
// 1 - delta_CL and escaping is on; else nullopt.
std::optional<double> Replanner::UnsafeHoldBound(const planning::PlanningRequest& req) const {
  const EscapeParams& e = params_.escape;
  if (e.horizon <= 0 || e.gain <= 0 || req.people.empty()) return std::nullopt;
  const double hold = HoldBound(planner_, req, q_->second, e.horizon);
  if (hold < 1 - planner_.params().delta_cl) return std::nullopt;
  return hold;
}

// Arrived? At the goal of a task with a retreat, the task goes on to it.
// Returns the cycle's result when the task is over (goal reached, time limit).
std::optional<CycleResult> Replanner::CheckProgress(int64_t now_ns, CycleResult* r) {
  Active& t = *task_;
  if (t.goal_q && (q_->second - *t.goal_q).cwiseAbs().maxCoeff() < params_.goal_tolerance &&
      qd_.cwiseAbs().maxCoeff() < params_.settle_speed) {
    if (t.spec.retreat.size() > 0 && !t.retreating) {
      t.retreating = true;
      t.goal_q = t.spec.retreat;
      r->status = "goal reached, retreating: ";
    } else {
      CycleResult done = Hold(now_ns, q_->second, t.retreating ? "retreat reached" : "goal reached");
      done.outcome = Finish(TaskStatus::kSucceeded, "", now_ns);
      return done;
    }
  }
  if (t.spec.time_limit > 0 && (now_ns - t.start_ns) * 1e-9 > t.spec.time_limit) {
    CycleResult late = Hold(now_ns, q_->second, "time limit");
    late.outcome = Finish(TaskStatus::kFailed, "time limit of " + std::to_string(t.spec.time_limit) + " s exceeded", now_ns);
    return late;
  }
  return std::nullopt;
}

// The request of this cycle: from the executing plan (its frozen prefix kept)
// when the robot follows it, else from the robot's state; the goal; the
// prediction when it is fresh. *start_ns is the time of waypoint 0.
planning::PlanningRequest Replanner::MakeRequest(int64_t now_ns, const planning::Goal& goal, int64_t* start_ns,
                                                CycleResult* r) {
  const double dt = planner_.params().dt;
  planning::PlanningRequest req;
  if (previous_) {
    // Where the executing plan says the robot is at the state's stamp.
    auto& [p_start, P] = *previous_;
    const cell::JointTrajectory plan = cell::JointTrajectory::Uniform(p_start, dt, P);
    double error = (plan.PositionAt(q_->first) - q_->second).cwiseAbs().maxCoeff();
    // A robot slowed down by the monitor (its path time-scaled) is behind
    // the plan's timing, on its path: the plan is re-timed to where the
    // robot is on it, and the frozen prefix continues from there.
    if (error > 0.5 * params_.max_tracking_error && !robot_stopped_ && qd_.squaredNorm() > 0) {
      // A time-scaled robot falls behind by at most (1 - scale) of the time
      // between two trajectories (it starts each on time): two planning steps
      // cover that; a robot that stood still longer is off the plan.
      const auto max_lag = static_cast<int64_t>(2e9 * params_.planning_step);
      const auto [lag_ns, lag_error] = PathLag(plan, q_->first, q_->second, max_lag);
      // ... and moving along it (a robot that stands still is off the plan).
      const int64_t at = q_->first - lag_ns;
      const Eigen::VectorXd v_plan = (plan.PositionAt(at + 10'000'000) - plan.PositionAt(at)) / 0.01;
      if (lag_error < error && qd_.dot(v_plan) >= kMinPathSpeedFraction * v_plan.squaredNorm()) {
        p_start += lag_ns;
        error = lag_error;
        r->status += "robot behind the plan by " + std::to_string(lag_ns / 1000000) + " ms (slowed): re-timed; ";
      }
    }
    if (error > params_.max_tracking_error) {
      previous_.reset();  // the robot did not follow (stopped, pushed): start over from it
      r->status += "robot off the plan: replanning from its state; ";
    }
  }
  if (previous_) {
    // Keep what executes while this cycle plans; replan the rest.
    const int64_t steps = std::max<int64_t>(0, std::llround((now_ns - previous_->first) * 1e-9 / dt));
    *start_ns = previous_->first + static_cast<int64_t>(std::llround(steps * dt * 1e9));
    req.warm_start = planning::Planner::ShiftTrajectory(previous_->second, dt, steps * dt);
    req.start_q = req.warm_start.col(0);
    req.start_qdot = req.warm_start.cols() > 1 ? Eigen::VectorXd((req.warm_start.col(1) - req.warm_start.col(0)) / dt)
                                               : Eigen::VectorXd::Zero(req.start_q.size());
    req.num_frozen = std::min<int>(params_.frozen_waypoints, static_cast<int>(req.warm_start.cols()));
  } else {
    req.start_q = q_->second;
    req.start_qdot = Eigen::VectorXd::Zero(req.start_q.size());
    req.num_frozen = 1;
  }
  req.goal = goal;
  req.time_budget = params_.cycle_budget;
  // Patience: the longer the person has held the task off, the closer the
  // plan may come to what the monitor allows.
  if (task_ && params_.ssm_patience > 0) {
    req.ssm_scale = std::max(0.0, 1.0 - (task_->delay - task_->patience_from) / params_.ssm_patience);
  }
  req.obstacles = obstacles_;
  const int64_t stale = static_cast<int64_t>(params_.stale_after * 1e9);
  predictions_.Expire(now_ns, stale);
  for (const auto& [id, e] : predictions_) {
    const cell::TimedPrediction& p = e.value;
    req.people.push_back({&p.spheres(), p.time_step(), p.StartRelativeTo(*start_ns)});
    r->prediction_t0_ns = std::max(r->prediction_t0_ns, p.t0_ns());
  }
  // A person the depth camera alone sees: the points' prediction, step k at
  // the cloud's stamp + (k + 1) time_step.
  if (PlansOnPoints(now_ns)) {
    const double dt_points = params_.human_points.time_step;
    req.people.push_back({&*points_prediction_, dt_points, (points_stamp_ns_ - *start_ns) * 1e-9 + dt_points});
    r->prediction_t0_ns = points_stamp_ns_;
  }
  r->num_people = static_cast<int>(req.people.size());
  // Standing still would reach the bound: half the cycle's budget stays
  // for an escape, should this plan fail.
  unsafe_hold_ = UnsafeHoldBound(req);
  if (req.time_budget > 0 && unsafe_hold_) req.time_budget *= 0.5;
  return req;
}

// How far (ns, in [0, max_lag_ns]) the robot at `q` (stamp `stamp_ns`) is
// behind `plan`'s timing along its path: the lag whose plan position is
// nearest to q (max joint error, rad, returned too), the smallest lag on a tie.
std::pair<int64_t, double> Replanner::PathLag(const cell::JointTrajectory& plan, int64_t stamp_ns,
                                              const Eigen::VectorXd& q, int64_t max_lag_ns) {
  constexpr int64_t kStep = 5'000'000;  // ns
  std::pair<int64_t, double> best{0, std::numeric_limits<double>::infinity()};
  for (int64_t lag = 0; lag <= max_lag_ns && stamp_ns - lag >= plan.start_ns; lag += kStep) {
    const double e = (plan.PositionAt(stamp_ns - lag) - q).cwiseAbs().maxCoeff();
    if (e < best.second) best = {lag, e};
  }
  return best;
}

// The trajectory to publish from the plan, and what it means for the task:
// waits and holding off count as waiting; without a safe trajectory the
// robot keeps the frozen prefix and holds at its end.
void Replanner::ApplyPlan(const planning::PlanningRequest& req, const planning::PlanningResult& res, CycleResult* r) {
  Active& t = *task_;
  const std::string prefix = r->status;
  if (res.success()) {
    r->positions = res.positions;
    t.max_bound = std::max(t.max_bound, res.max_bound);
    r->max_bound = res.max_bound;
    if (res.num_waits > 0) {
      r->waiting = true;
      t.waiting = true;
      ++t.waits;
      r->status = prefix + "planned with " + std::to_string(res.num_waits) + " wait(s)";
    } else if (res.ssm_margin < planner_.params().ssm_activation) {
      // The separation monitor's rule (predicted) shapes this plan: the
      // robot slows down, goes round, holds off or withdraws so that the
      // monitor need not stop it. Counted as delay, not as a wait.
      r->held_off = true;
      t.waiting = true;
      r->status = prefix + "planned, held off by the monitor's rule (predicted margin " +
                  std::to_string(res.ssm_margin) + " m)";
    } else if (res.human_separation < planner_.params().human_separation) {
      // The keep-out from the person shapes this plan: the robot goes round
      // or holds off instead of taking its free path. Counted as delay (the
      // extra time the task needs because of the person), not as a wait.
      r->held_off = true;
      t.waiting = true;
      r->status = prefix + "planned, held off by the person (separation " + std::to_string(res.human_separation) + " m)";
    } else {
      r->status = prefix + "planned";
    }
    return;
  }
  if (std::optional<planning::PlanningResult> escape = Escape(req, res)) {
    r->positions = escape->positions;
    r->max_bound = escape->max_bound;
    r->held_off = true;
    t.waiting = true;
    r->status = prefix + "escaping the person's predicted way (bound " + std::to_string(escape->max_bound) +
                "; no safe trajectory: " + res.reason + ")";
    return;
  }
  const Eigen::MatrixXd& base = previous_ ? req.warm_start : q_->second.replicate(1, 1);
  const int keep = std::max(1, std::min<int>(req.num_frozen, static_cast<int>(base.cols())));
  r->positions.resize(base.rows(), keep + 1);
  r->positions.leftCols(keep) = base.leftCols(keep);
  r->positions.col(keep) = base.col(keep - 1);
  r->waiting = true;
  t.waiting = true;
  ++t.waits;
  r->status = prefix + "no safe trajectory: holding (" + res.reason + ")";
}

}  // namespace iplan::trajopt
