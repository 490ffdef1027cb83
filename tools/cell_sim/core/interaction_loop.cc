#include "tools/cell_sim/core/interaction_loop.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "services/supervisor/core/safety_monitor.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/trajectory_bound.h"

namespace iplan::cell_sim {
namespace {

// 1000 s: far from 0 (a "none" stamp for the cores) and exact in double s.
constexpr int64_t kEpochNs = 1'000'000'000'000;

int64_t Ns(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e9)); }

std::string Positive(const char* name, double v) {
  return v > 0 && std::isfinite(v) ? std::string() : std::string(name) + " must be > 0, got " + std::to_string(v);
}

// The true bound at one instant: the robot's spheres at q against the body
// spheres of one Gaussian skeleton (a one-action, one-step prediction).
class TrueBound {
 public:
  TrueBound(const collision::RobotModel& robot, const collision::HumanBodyModel& body)
      : robot_(robot),
        body_(body),
        data_(robot),
        prediction_(body.MakePrediction(1, 1)),
        workspace_(static_cast<int>(robot.spheres.size()), body.num_spheres()) {
    for (const auto& s : robot.spheres) {
      trajectory_.radii.push_back(s.radius);
      trajectory_.links.push_back(s.link);
    }
    trajectory_.steps = {0};
    trajectory_.centres.resize(3, static_cast<Eigen::Index>(robot.spheres.size()));
    prediction_.set_action_probability(0, 1.0);
  }

  double Evaluate(const Eigen::VectorXd& q, const Eigen::Matrix3Xd& p_WJ, const std::vector<Eigen::Matrix3d>& covs) {
    if (!body_.FillPrediction(p_WJ, covs, 0, 0, &prediction_)) {
      throw std::runtime_error("true bound: a body sphere covariance is not positive definite");
    }
    prediction_.UpdateSummaries();
    collision::CalcForwardKinematics(robot_, q, &data_);
    trajectory_.centres = data_.p_WS;
    collision::EvaluateTrajectoryBound(prediction_, trajectory_, collision::TrajectoryBoundParams{}, &workspace_, &out_);
    return std::clamp(out_[0].bound, 0.0, 1.0);
  }

 private:
  const collision::RobotModel& robot_;
  const collision::HumanBodyModel& body_;
  collision::RobotData data_;
  collision::HumanPrediction prediction_;
  collision::RobotSpheresTrajectory trajectory_;
  collision::TrajectoryBoundWorkspace workspace_;
  std::vector<collision::WaypointBound> out_;
};

std::vector<double> ToStd(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

}  // namespace

int64_t SimTimeNs(double t) { return kEpochNs + Ns(t); }

void PersonStream::TrueAt(double t, Eigen::Matrix3Xd* p_WJ) const {
  const int n = num_frames();
  const double s = std::clamp(t * rate_hz, 0.0, static_cast<double>(n - 1));
  const int i = std::min(static_cast<int>(s), n - 1);
  const int j = std::min(i + 1, n - 1);
  const double u = s - i;
  *p_WJ = (1 - u) * truth[static_cast<std::size_t>(i)] + u * truth[static_cast<std::size_t>(j)];
}

std::string PersonStream::Validate() const {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) return "person stream: rate_hz must be > 0";
  if (truth.empty()) return "person stream: no frames";
  if (observed.size() != truth.size()) return "person stream: observed and true frames differ in number";
  const Eigen::Index J = static_cast<Eigen::Index>(joint_names.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i].cols() != J || observed[i].cols() != J) {
      return "person stream: frame " + std::to_string(i) + " does not have " + std::to_string(J) + " joints";
    }
    if (!truth[i].allFinite() || !observed[i].allFinite()) return "person stream: frame " + std::to_string(i) + " is not finite";
  }
  return "";
}

std::string LoopParams::Validate() const {
  for (const std::string& why : {Positive("control_rate_hz", control_rate_hz), Positive("joint_state_rate_hz", joint_state_rate_hz),
                                 Positive("monitor_rate_hz", monitor_rate_hz), Positive("max_duration", max_duration),
                                 Positive("true_bound_std", true_bound_std)}) {
    if (!why.empty()) return why;
  }
  if (!(resume_delay >= 0)) return "resume_delay must be >= 0";
  if (!(task_start >= 0)) return "task_start must be >= 0";
  if (joint_state_rate_hz > control_rate_hz) return "joint_state_rate_hz must not exceed control_rate_hz";
  return "";
}

namespace {

// One run of the loop: the cores, the event clocks and the result so far.
// Events are taken in time order; at equal times control, then the
// person's frame, then the monitor, then planning.
class Interaction {
 public:
  Interaction(const CellModels& models, const LoopParams& params, const Eigen::VectorXd& start_q, const TaskFeed& feed,
              const PersonStream& person, const PredictionSource& planner_prediction,
              const PredictionSource& monitor_prediction, const CovarianceSource& true_covariance)
      : params_(params),
        feed_(feed),
        person_(person),
        planner_prediction_(planner_prediction),
        monitor_prediction_(monitor_prediction),
        true_covariance_(true_covariance),
        body_(*models.body),
        robot_(models.planner->robot(), start_q, models.simulator),
        replanner_(*models.planner, body_, models.replanner),
        monitor_(*models.monitor),
        supervisor_({}),
        true_bound_(models.planner->robot(), body_),
        robot_joints_(robot_.joint_names()),
        isotropic_(person.joint_names.size(), params.true_bound_std * params.true_bound_std * Eigen::Matrix3d::Identity()),
        control_period_(Ns(1.0 / params.control_rate_hz)),
        state_every_(std::max(1, static_cast<int>(std::lround(params.control_rate_hz / params.joint_state_rate_hz)))),
        plan_period_(Ns(models.replanner.planning_step)),
        monitor_period_(Ns(1.0 / params.monitor_rate_hz)),
        task_start_((Ns(params.task_start) + plan_period_ - 1) / plan_period_ * plan_period_),
        end_(task_start_ + Ns(params.max_duration)),
        skeleton_(person.joint_names.size()) {
    supervisor_.SetResumeDelay(params.resume_delay);
  }

  EpisodeResult Run() {
    while (true) {
      const int64_t t = std::min({next_control_, FrameTime(frame_), next_monitor_, next_plan_});
      if (t >= end_) {
        finish_ = end_;
        if (in_task_) {
          result_.reason = "no outcome within " + std::to_string(params_.max_duration) + " s";
          // What is left of the run's limit (all of it for the first task).
          result_.task_time = params_.max_duration - (command_ - task_start_) * 1e-9;
          CloseTask(end_);
        }
        break;
      }
      if (t == next_control_) {
        Control(t);
      } else if (t == FrameTime(frame_)) {
        Frame(t);
      } else if (t == next_monitor_) {
        // Between predictions the monitor keeps watching at its own rate.
        if (t - last_evaluation_ >= monitor_period_ * 9 / 10) Evaluate(t);
        next_monitor_ += monitor_period_;
      } else if (Plan(t)) {
        break;
      }
    }
    episode_.duration = (finish_ - task_start_) * 1e-9;
    return episode_;
  }

 private:
  int64_t FrameTime(int i) const { return i < person_.num_frames() ? Ns(person_.stamp(i)) : INT64_MAX; }

  // One monitor evaluation and what it means for the robot.
  void Evaluate(int64_t t) {
    const collision_risk::RiskReport report = monitor_.Evaluate(kEpochNs + t);
    last_evaluation_ = t;
    const bool risk_stop = report.verdict == collision_risk::Verdict::kProtectiveStop;
    supervisor_.OnRiskVerdict(report.verdict, report.reason, report.retreating);
    // Both permits: the monitor's own (a stop at once) and the supervisor's
    // (which holds a stop until every cause has been clear for the delay).
    const bool held = supervisor_.Evaluate(nullptr, kEpochNs + t).stop;
    const bool stop = risk_stop || held;
    if (params_.trace && stop != robot_.stopped()) {
      params_.trace(t * 1e-9, stop ? "STOP: " + (risk_stop ? report.reason : std::string("held by the resume delay"))
                                   : "resume: " + report.reason);
    } else if (params_.trace && stop && report.reason != last_stop_reason_) {
      params_.trace(t * 1e-9, "still stopped: " + (risk_stop ? report.reason : std::string("held by the resume delay")));
    }
    last_stop_reason_ = stop ? (risk_stop ? report.reason : std::string("held")) : std::string();
    if (stop && !robot_.stopped()) {
      robot_.Stop();
      stop_since_ = t;
      if (in_task_) {
        ++result_.protective_stops;
        // Which layer (the monitor decides separation first, then the bound).
        if (report.separation_margin && *report.separation_margin < 0) {
          ++result_.stops_separation;
        } else if (!report.waypoint_bounds.empty()) {
          ++result_.stops_bound;
        }
        if (result_.first_stop_reason.empty()) result_.first_stop_reason = report.reason;
      }
    } else if (!stop && robot_.stopped()) {
      robot_.Resume();
      if (in_task_) result_.stop_time += (t - stop_since_) * 1e-9;
    }
    replanner_.SetRobotStopped(stop);
    // Speed reduction: the monitor's scale holds until its next evaluation.
    const double scale = stop ? 1.0 : report.speed_scale;
    if (in_task_ && robot_.speed_scale() < 1.0) result_.slow_time += (t - slow_since_) * 1e-9;
    if (params_.trace && (scale < 1.0) != (robot_.speed_scale() < 1.0)) {
      params_.trace(t * 1e-9, scale < 1.0 ? "SLOW DOWN: " + report.reason : "full speed: " + report.reason);
    }
    if (in_task_ && scale < 1.0 && robot_.speed_scale() == 1.0) ++result_.slow_downs;
    slow_since_ = t;
    robot_.SetSpeedScale(scale);
  }

  // The robot moves, the true body decides contact, and (at its rate) the
  // robot state goes to the planner and the monitor.
  void Control(int64_t t) {
    const int64_t stamp = kEpochNs + t;
    if (control_step_ > 0) robot_.Step(stamp, control_period_ * 1e-9);
    person_.TrueAt(t * 1e-9, &p_WJ_);
    const int contacts = robot_.contacts();
    const double separation = robot_.UpdateContacts(p_WJ_, body_);
    const double speed = robot_.qd().cwiseAbs().maxCoeff();
    if (in_task_) result_.min_separation = std::min(result_.min_separation, separation);
    if (started_) episode_.min_separation = std::min(episode_.min_separation, separation);
    // A new contact: was the robot moving into the person, or standing
    // still while the person moved into it?
    if (robot_.contacts() > contacts) {
      const bool moving = speed > kMovingContactSpeed;
      if (params_.trace) {
        params_.trace(t * 1e-9, std::string("CONTACT with the robot ") + (moving ? "moving" : "at rest") +
                                    (robot_.stopped() ? " (stopped)" : "") + ", separation " + std::to_string(separation) + " m");
      }
      if (in_task_) {
        result_.contact_speeds.push_back(speed);
        ++(moving ? result_.robot_moving_contacts : result_.robot_at_rest_contacts);
      }
      if (started_) ++(moving ? episode_.robot_moving_contacts : episode_.robot_at_rest_contacts);
    }
    // The step that just ran: standing still with a task, not stopped and
    // not arriving (at its goal or retreat).
    if (in_task_ && control_step_ > 0 && !robot_.stopped() && speed <= kMovingContactSpeed && !Arriving()) {
      result_.wait_time += control_period_ * 1e-9;
    }
    if (control_step_ % state_every_ == 0) {
      const std::vector<double> q = ToStd(robot_.q()), qd = ToStd(robot_.qd());
      if (auto why = replanner_.UpdateRobotState(stamp, robot_joints_, q, qd)) throw std::runtime_error("replanner: " + *why);
      if (auto why = monitor_.UpdateRobotState(stamp, robot_joints_, q)) throw std::runtime_error("monitor: " + *why);
    }
    ++control_step_;
    next_control_ += control_period_;
  }

  // A skeleton frame: to the monitor, and the predictions made from it.
  void Frame(int64_t t) {
    const int64_t stamp = kEpochNs + t;
    const Eigen::Matrix3Xd& seen = person_.observed[static_cast<std::size_t>(frame_)];
    for (Eigen::Index j = 0; j < seen.cols(); ++j) skeleton_[static_cast<std::size_t>(j)] = seen.col(j);
    if (auto why = monitor_.UpdateSkeleton(stamp, person_.joint_names, skeleton_)) throw std::runtime_error("monitor: " + *why);
    if (const collision::JointMixture* p = planner_prediction_ ? planner_prediction_(frame_) : nullptr) {
      if (auto why = replanner_.UpdatePrediction(*p)) throw std::runtime_error("replanner prediction: " + *why);
    }
    // The monitor evaluates with every prediction it receives.
    if (const collision::JointMixture* p = monitor_prediction_ ? monitor_prediction_(frame_) : nullptr) {
      if (auto why = monitor_.UpdatePrediction(*p)) throw std::runtime_error("monitor prediction: " + *why);
      Evaluate(t);
    }
    if (in_task_) {
      const std::vector<Eigen::Matrix3d>* covs = true_covariance_ ? true_covariance_(frame_) : nullptr;
      result_.max_bound = std::max(result_.max_bound, true_bound_.Evaluate(robot_.q(), person_.truth[static_cast<std::size_t>(frame_)],
                                                                           covs ? *covs : isotropic_));
    }
    ++frame_;
  }

  // A planning step (a task is commanded at it when the feed has one
  // due); true when the run ends.
  bool Plan(int64_t t) {
    const int64_t stamp = kEpochNs + t;
    next_plan_ += plan_period_;
    if (!in_task_ && t >= task_start_ && t >= next_task_at_) {
      std::optional<trajopt::TaskSpec> task = feed_.next(t * 1e-9, frame_ - 1);
      if (!task) {
        finish_ = t;
        episode_.ended_by_feed = true;
        return true;
      }
      StartTask(std::move(*task), t);
    }
    const trajopt::CycleResult r = replanner_.Cycle(stamp);
    if (params_.trace) {
      const Eigen::VectorXd& goal = task_.goal.q;
      const double error = goal.size() == robot_.q().size() ? (robot_.q() - goal).cwiseAbs().maxCoeff() : -1.0;
      params_.trace(t * 1e-9, "plan: " + r.status + " (bound " + std::to_string(r.max_bound) + ", robot " +
                                  std::to_string(error) + " rad from the goal, " +
                                  std::to_string(robot_.qd().cwiseAbs().maxCoeff()) + " rad/s)");
    }
    if (r.planning_time > 0) {
      if (in_task_) {
        result_.planning_times.push_back(r.planning_time);
        ++result_.planning_cycles;
      } else {
        pending_times_.push_back(r.planning_time);
      }
    }
    if (r.publish) Publish(r);
    if (!(r.outcome && in_task_ && r.outcome->id == task_.id)) return false;
    result_.finished = true;
    result_.status = r.outcome->status;
    result_.reason = r.outcome->reason;
    result_.task_time = r.outcome->duration;
    result_.planner_delay = r.outcome->delay;
    result_.waits = r.outcome->num_waits;
    finish_ = t;
    CloseTask(t);
    if (!(feed_.done && feed_.done(t * 1e-9, frame_ - 1, *r.outcome))) {
      episode_.ended_by_feed = true;
      return true;
    }
    next_task_at_ = t + Ns(feed_.pause);
    return false;
  }

  void StartTask(trajopt::TaskSpec task, int64_t t) {
    task_ = std::move(task);
    replanner_.StartTask(task_, kEpochNs + t);
    // The planning cycles since the previous task (or the start) count as
    // this task's, as they always have for a single task.
    result_ = InteractionResult{};
    result_.planning_times = std::move(pending_times_);
    result_.planning_cycles = static_cast<int>(result_.planning_times.size());
    pending_times_.clear();
    result_.command_time = t * 1e-9;
    in_task_ = true;
    started_ = true;
    command_ = t;
    slow_since_ = t;
    contacts_before_ = robot_.contacts();
    if (robot_.stopped()) {
      ++result_.protective_stops;
      stop_since_ = t;
      result_.first_stop_reason = "stopped when the task was commanded";
    }
  }

  // The robot is within kArrivingDistance of the running task's goal or
  // retreat (every joint).
  bool Arriving() const {
    const Eigen::VectorXd& q = robot_.q();
    for (const Eigen::VectorXd* target : {&task_.goal.q, &task_.retreat}) {
      if (target->size() == q.size() && (q - *target).cwiseAbs().maxCoeff() <= kArrivingDistance) return true;
    }
    return false;
  }

  // The running task's figures are complete at `t`: its open intervals
  // closed, its contacts counted.
  void CloseTask(int64_t t) {
    if (robot_.stopped()) result_.stop_time += (t - stop_since_) * 1e-9;
    if (robot_.speed_scale() < 1.0) result_.slow_time += (t - slow_since_) * 1e-9;
    result_.true_contacts = robot_.contacts() - contacts_before_;
    episode_.tasks.push_back(result_);
    in_task_ = false;
  }

  // A new trajectory: to the robot and to the monitor.
  void Publish(const trajopt::CycleResult& r) {
    std::vector<double> times;
    std::vector<std::vector<double>> points;
    for (Eigen::Index i = 0; i < r.positions.cols(); ++i) {
      times.push_back(static_cast<double>(i) * r.dt);
      points.push_back(ToStd(r.positions.col(i)));
    }
    if (auto why = robot_.SetTrajectory(r.start_ns, robot_joints_, times, points)) throw std::runtime_error("robot: " + *why);
    if (auto why = monitor_.UpdateTrajectory(r.start_ns, robot_joints_, times, points)) {
      throw std::runtime_error("monitor trajectory: " + *why);
    }
  }

  const LoopParams& params_;
  const TaskFeed& feed_;
  const PersonStream& person_;
  const PredictionSource& planner_prediction_;
  const PredictionSource& monitor_prediction_;
  const CovarianceSource& true_covariance_;
  const collision::HumanBodyModel& body_;
  robot_sim::RobotSimulator robot_;
  trajopt::Replanner replanner_;
  collision_risk::RiskMonitor monitor_;
  supervisor::SafetyMonitor supervisor_;
  TrueBound true_bound_;
  const std::vector<std::string> robot_joints_;
  const std::vector<Eigen::Matrix3d> isotropic_;
  // Event clocks: ns of scenario time; the cores get kEpochNs + t (SimTimeNs).
  const int64_t control_period_;
  const int state_every_;
  const int64_t plan_period_, monitor_period_, task_start_, end_;
  int64_t next_control_ = 0, next_plan_ = 0, next_monitor_ = 0;
  int control_step_ = 0, frame_ = 0;

  InteractionResult result_;  // the running (or last) task's
  EpisodeResult episode_;
  trajopt::TaskSpec task_;    // the running (or last) task
  bool in_task_ = false;
  bool started_ = false;      // a task has been commanded
  int contacts_before_ = 0;  // contacts before the command (the robot at rest) are not the task's
  int64_t command_ = 0;       // scenario time of the running task's command
  int64_t next_task_at_ = 0;  // scenario time from which the next task may be commanded
  int64_t finish_ = 0;       // scenario time the run ended
  std::vector<double> pending_times_;  // s, planning cycles while no task ran
  int64_t last_evaluation_ = INT64_MIN / 2, stop_since_ = 0, slow_since_ = 0;
  std::string last_stop_reason_;  // for the trace: the stop's cause as last traced
  std::vector<Eigen::Vector3d> skeleton_;
  Eigen::Matrix3Xd p_WJ_;
};

}  // namespace

namespace {

void CheckRun(const CellModels& models, const LoopParams& params, const PersonStream& person) {
  if (!models.planner || !models.body || !models.monitor) throw std::invalid_argument("RunInteraction: a model is missing");
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("RunInteraction: " + why);
  if (const std::string why = person.Validate(); !why.empty()) throw std::invalid_argument("RunInteraction: " + why);
  if (person.joint_names != models.body->params().joints) {
    throw std::invalid_argument("RunInteraction: the person's joints are not the body model's, in its order");
  }
}

}  // namespace

EpisodeResult RunEpisode(const CellModels& models, const LoopParams& params, const Eigen::VectorXd& start_q,
                         const TaskFeed& feed, const PersonStream& person, const PredictionSource& planner_prediction,
                         const PredictionSource& monitor_prediction, const CovarianceSource& true_covariance) {
  CheckRun(models, params, person);
  if (!feed.next) throw std::invalid_argument("RunEpisode: the task feed has no next()");
  if (!(feed.pause >= 0)) throw std::invalid_argument("RunEpisode: the pause between tasks must be >= 0");
  return Interaction(models, params, start_q, feed, person, planner_prediction, monitor_prediction, true_covariance).Run();
}

InteractionResult RunInteraction(const CellModels& models, const LoopParams& params, const TaskSetup& setup,
                                 const PersonStream& person, const PredictionSource& planner_prediction,
                                 const PredictionSource& monitor_prediction, const CovarianceSource& true_covariance) {
  CheckRun(models, params, person);
  // One task: commanded at the first planning step from task_start on; its
  // outcome (or the limit) ends the run.
  bool given = false;
  TaskFeed feed;
  feed.next = [&](double, int) -> std::optional<trajopt::TaskSpec> {
    if (given) return std::nullopt;
    given = true;
    return setup.task;
  };
  EpisodeResult episode =
      Interaction(models, params, setup.start_q, feed, person, planner_prediction, monitor_prediction, true_covariance)
          .Run();
  if (episode.tasks.empty()) throw std::runtime_error("RunInteraction: the task was never commanded");
  return std::move(episode.tasks.front());
}

}  // namespace iplan::cell_sim
