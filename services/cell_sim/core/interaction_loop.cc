#include "core/interaction_loop.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "core/safety_monitor.h"
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

InteractionResult RunInteraction(const CellModels& models, const LoopParams& params, const TaskSetup& setup,
                                 const PersonStream& person, const PredictionSource& planner_prediction,
                                 const PredictionSource& monitor_prediction, const CovarianceSource& true_covariance) {
  if (!models.planner || !models.body || !models.monitor) throw std::invalid_argument("RunInteraction: a model is missing");
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("RunInteraction: " + why);
  if (const std::string why = person.Validate(); !why.empty()) throw std::invalid_argument("RunInteraction: " + why);
  if (person.joint_names != models.body->params().joints) {
    throw std::invalid_argument("RunInteraction: the person's joints are not the body model's, in its order");
  }
  const planning::Planner& planner = *models.planner;
  const collision::HumanBodyModel& body = *models.body;

  robot_sim::RobotSimulator robot(planner.robot(), setup.start_q, models.simulator);
  trajopt::Replanner replanner(planner, body, models.replanner);
  collision_risk::RiskMonitor monitor = *models.monitor;
  supervisor::SafetyMonitor supervisor({});
  supervisor.SetResumeDelay(params.resume_delay);
  TrueBound true_bound(planner.robot(), body);
  const std::vector<std::string> robot_joints = robot.joint_names();
  const std::vector<Eigen::Matrix3d> isotropic(person.joint_names.size(),
                                               params.true_bound_std * params.true_bound_std * Eigen::Matrix3d::Identity());

  // Event clocks: ns of scenario time; the cores get kEpochNs + t (SimTimeNs).
  const int64_t control_period = Ns(1.0 / params.control_rate_hz);
  const int state_every = std::max(1, static_cast<int>(std::lround(params.control_rate_hz / params.joint_state_rate_hz)));
  const int64_t plan_period = Ns(models.replanner.planning_step);
  const int64_t monitor_period = Ns(1.0 / params.monitor_rate_hz);
  const int64_t task_start = (Ns(params.task_start) + plan_period - 1) / plan_period * plan_period;
  const int64_t end = task_start + Ns(params.max_duration);
  int64_t next_control = 0, next_plan = 0, next_monitor = 0;
  int control_step = 0, frame = 0;
  auto frame_time = [&](int i) { return i < person.num_frames() ? Ns(person.stamp(i)) : INT64_MAX; };

  InteractionResult result;
  bool in_task = false;
  int contacts_before = 0;  // contacts before the command (the robot at rest) are not the task's
  int64_t finish = end;     // scenario time the run ended
  int64_t last_evaluation = INT64_MIN / 2, stop_since = 0;
  std::vector<Eigen::Vector3d> skeleton(person.joint_names.size());
  Eigen::Matrix3Xd p_WJ;

  // One monitor evaluation and what it means for the robot.
  auto evaluate = [&](int64_t t) {
    const collision_risk::RiskReport report = monitor.Evaluate(kEpochNs + t);
    last_evaluation = t;
    const bool risk_stop = report.verdict == collision_risk::Verdict::kProtectiveStop;
    supervisor.OnRiskVerdict(report.verdict, report.reason);
    // Both permits: the monitor's own (a stop at once) and the supervisor's
    // (which holds a stop until every cause has been clear for the delay).
    const bool held = supervisor.Evaluate(nullptr, kEpochNs + t).stop;
    const bool stop = risk_stop || held;
    if (params.trace && stop != robot.stopped()) {
      params.trace(t * 1e-9, stop ? "STOP: " + (risk_stop ? report.reason : std::string("held by the resume delay"))
                                  : "resume: " + report.reason);
    }
    if (stop && !robot.stopped()) {
      robot.Stop();
      stop_since = t;
      if (in_task) {
        ++result.protective_stops;
        // Which layer (the monitor decides separation first, then the bound).
        if (report.separation_margin && *report.separation_margin < 0) {
          ++result.stops_separation;
        } else if (!report.waypoint_bounds.empty()) {
          ++result.stops_bound;
        }
        if (result.first_stop_reason.empty()) result.first_stop_reason = report.reason;
      }
    } else if (!stop && robot.stopped()) {
      robot.Resume();
      if (in_task) result.stop_time += (t - stop_since) * 1e-9;
    }
    replanner.SetRobotStopped(stop);
  };

  while (true) {
    const int64_t t = std::min({next_control, frame_time(frame), next_monitor, next_plan});
    if (t >= end) {
      finish = end;
      result.reason = "no outcome within " + std::to_string(params.max_duration) + " s";
      result.task_time = params.max_duration;
      break;
    }
    const int64_t stamp = kEpochNs + t;
    if (t == next_control) {
      // The robot moves, the true body decides contact, and (at its rate) the
      // robot state goes to the planner and the monitor.
      if (control_step > 0) robot.Step(stamp, control_period * 1e-9);
      person.TrueAt(t * 1e-9, &p_WJ);
      const double separation = robot.UpdateContacts(p_WJ, body);
      if (in_task) result.min_separation = std::min(result.min_separation, separation);
      if (control_step % state_every == 0) {
        const std::vector<double> q = ToStd(robot.q()), qd = ToStd(robot.qd());
        if (auto why = replanner.UpdateRobotState(stamp, robot_joints, q, qd)) throw std::runtime_error("replanner: " + *why);
        if (auto why = monitor.UpdateRobotState(stamp, robot_joints, q)) throw std::runtime_error("monitor: " + *why);
      }
      ++control_step;
      next_control += control_period;
      continue;
    }
    if (t == frame_time(frame)) {
      const Eigen::Matrix3Xd& seen = person.observed[static_cast<std::size_t>(frame)];
      for (Eigen::Index j = 0; j < seen.cols(); ++j) skeleton[static_cast<std::size_t>(j)] = seen.col(j);
      if (auto why = monitor.UpdateSkeleton(stamp, person.joint_names, skeleton)) throw std::runtime_error("monitor: " + *why);
      if (const collision::JointMixture* p = planner_prediction ? planner_prediction(frame) : nullptr) {
        if (auto why = replanner.UpdatePrediction(*p)) throw std::runtime_error("replanner prediction: " + *why);
      }
      // The monitor evaluates with every prediction it receives.
      if (const collision::JointMixture* p = monitor_prediction ? monitor_prediction(frame) : nullptr) {
        if (auto why = monitor.UpdatePrediction(*p)) throw std::runtime_error("monitor prediction: " + *why);
        evaluate(t);
      }
      if (in_task) {
        const std::vector<Eigen::Matrix3d>* covs = true_covariance ? true_covariance(frame) : nullptr;
        result.max_bound = std::max(result.max_bound, true_bound.Evaluate(robot.q(), person.truth[static_cast<std::size_t>(frame)],
                                                                          covs ? *covs : isotropic));
      }
      ++frame;
      continue;
    }
    if (t == next_monitor) {
      // Between predictions the monitor keeps watching at its own rate.
      if (t - last_evaluation >= monitor_period * 9 / 10) evaluate(t);
      next_monitor += monitor_period;
      continue;
    }
    // Planning step.
    next_plan += plan_period;
    if (t == task_start) {
      replanner.StartTask(setup.task, stamp);
      in_task = true;
      contacts_before = robot.contacts();
      if (robot.stopped()) {
        ++result.protective_stops;
        stop_since = t;
        result.first_stop_reason = "stopped when the task was commanded";
      }
    }
    const trajopt::CycleResult r = replanner.Cycle(stamp);
    if (params.trace) {
      const Eigen::VectorXd& goal = setup.task.goal.q;
      const double error = goal.size() == robot.q().size() ? (robot.q() - goal).cwiseAbs().maxCoeff() : -1.0;
      params.trace(t * 1e-9, "plan: " + r.status + " (bound " + std::to_string(r.max_bound) + ", robot " +
                                 std::to_string(error) + " rad from the goal, " + std::to_string(robot.qd().cwiseAbs().maxCoeff()) + " rad/s)");
    }
    if (r.planning_time > 0) {
      result.planning_times.push_back(r.planning_time);
      ++result.planning_cycles;
    }
    if (r.publish) {
      std::vector<double> times;
      std::vector<std::vector<double>> points;
      for (Eigen::Index i = 0; i < r.positions.cols(); ++i) {
        times.push_back(static_cast<double>(i) * r.dt);
        points.push_back(ToStd(r.positions.col(i)));
      }
      if (auto why = robot.SetTrajectory(r.start_ns, robot_joints, times, points)) throw std::runtime_error("robot: " + *why);
      if (auto why = monitor.UpdateTrajectory(r.start_ns, robot_joints, times, points)) {
        throw std::runtime_error("monitor trajectory: " + *why);
      }
    }
    if (r.outcome && in_task) {
      result.finished = true;
      result.status = r.outcome->status;
      result.reason = r.outcome->reason;
      result.task_time = r.outcome->duration;
      result.planner_delay = r.outcome->delay;
      result.waits = r.outcome->num_waits;
      finish = t;
      break;
    }
  }
  if (in_task && robot.stopped()) result.stop_time += (finish - stop_since) * 1e-9;
  result.true_contacts = robot.contacts() - contacts_before;
  return result;
}

}  // namespace iplan::cell_sim
