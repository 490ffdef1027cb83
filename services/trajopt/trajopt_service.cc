// iplan-trajopt: the trajectory-optimisation service. Every planning step it
// replans the robot's trajectory against the newest prediction (ITOMP,
// common/planning), publishes it, and reports each task's outcome.
#include <chrono>
#include <deque>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "iplan/adapters/adapters.h"
#include "services/trajopt/core/obstacle_set.h"
#include "iplan/framework/service.h"
#include "trajopt_config.h"

namespace iplan::trajopt {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class TrajoptService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    const TrajoptConfig c = ReadTrajoptConfig(config);
    planning_step_ = c.replanner.planning_step;
    use_prediction_ = c.use_prediction;
    replan_on_prediction_ = c.replan_on_prediction;
    obstacles_ = ObstacleSet(c.obstacle_timeout);
    output_ = c.output;
    if (!use_prediction_) node.log().warn("trajopt.use_prediction is false: plans ignore the person (ablation)");
    try {
      planner_ = MakePlanner(c);
      body_ = std::make_unique<collision::HumanBodyModel>(collision::LoadHumanBodyParams(c.human_body_file));
      replanner_ = std::make_unique<Replanner>(*planner_, *body_, c.replanner);
    } catch (const std::exception& e) {
      return Result::Fail(e.what());
    }
    trajectory_writer_ = &node.Advertise(framework::topics::RobotTrajectory());
    outcome_writer_ = &node.Advertise(framework::topics::TaskOutcome());
    status_writer_ = &node.Advertise(framework::topics::PlanStatus());
    using SI = const dds::SampleInfo&;
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, SI)>([this, &node](const msg::JointState& m, SI) {
                     node.CountRejection("joint_states",
                           replanner_->UpdateRobotState(msg::ToNanoseconds(m.header.stamp), m.name, m.position, m.velocity));
                   }));
    node.Subscribe(framework::topics::HumanPrediction(),
                   std::function<void(const msg::HumanPrediction&, SI)>([this, &node](const msg::HumanPrediction& m, SI) {
                     if (!use_prediction_) return;
                     const auto why = replanner_->UpdatePrediction(m.body_id, services::ToJointMixture(m));
                     node.CountRejection("prediction", why);
                     if (why) return;
                     latest_prediction_ = {msg::ToNanoseconds(m.observation_stamp), msg::ToNanoseconds(m.header.stamp)};
                     // Replan at once with the new prediction (not at the next tick), unless a cycle
                     // ran less than half a planning step ago.
                     const auto now = std::chrono::steady_clock::now();
                     if (replan_on_prediction_ && active_ && now - last_cycle_ >= MinCycleGap()) Step(node);
                   }));
    // The people the depth camera alone sees (camera-only cell): planned
    // against while no skeleton prediction is fresh, a cycle at once as for
    // a prediction.
    node.Subscribe(framework::topics::HumanPoints(),
                   std::function<void(const msg::HumanPoints&, SI)>([this, &node](const msg::HumanPoints& m, SI) {
                     if (!use_prediction_) return;
                     const auto why = replanner_->UpdateHumanPoints(services::FromHumanPoints(m));
                     node.CountRejection("human_points", why);
                     const int64_t now_ns = msg::ToNanoseconds(msg::Now());
                     if (why || !replanner_->PlansOnPoints(now_ns)) return;
                     latest_prediction_ = {msg::ToNanoseconds(m.header.stamp), now_ns};
                     const auto now = std::chrono::steady_clock::now();
                     if (replan_on_prediction_ && active_ && now - last_cycle_ >= MinCycleGap()) Step(node);
                   }));
    node.Subscribe(framework::topics::Obstacles(),
                   std::function<void(const msg::ObstacleArray&, SI)>([this, &node](const msg::ObstacleArray& m, SI) {
                     OnObstacles(node, m);
                   }));
    // The supervisor's permit tells whether the cell is stopped (its stop
    // covers the collision-risk verdict too): stop time counts as delay.
    node.Subscribe(framework::topics::SupervisorPermit(), std::function<void(const msg::SafetyPermit&, SI)>([this](const msg::SafetyPermit& m, SI) {
                     replanner_->SetRobotStopped(m.state == msg::SafetyPermit::STOP);
                   }));
    node.Subscribe(framework::topics::TaskCommand(),
                   std::function<void(const msg::TaskCommand& m, SI)>([this, &node](const msg::TaskCommand& m, SI) {
                     OnCommand(node, m);
                   }),
                   framework::SubscribeOptions{false});
    return Result::Ok();
  }

  // Cycles run when a prediction arrives (replan_on_prediction) and, when
  // none has arrived for 1.5 planning steps (nobody seen, intent down,
  // ablation), on the planning step's tick. The margin keeps a tick from
  // planning with an old prediction just before a late one arrives.
  Result OnActivate(Node& node) override {
    active_ = true;
    timer_ = node.AddTimer(std::chrono::nanoseconds(static_cast<int64_t>(planning_step_ * 1e9)), [this, &node] {
      const auto since = std::chrono::steady_clock::now() - last_cycle_;
      if (!replan_on_prediction_ || since >= std::chrono::duration<double>(1.5 * planning_step_)) Step(node);
    });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    active_ = false;
    node.CancelTimer(timer_);
    return Result::Ok();
  }

  std::chrono::steady_clock::duration MinCycleGap() const {
    return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(0.5 * planning_step_));
  }

 private:
  // A changed obstacle set replans at once: a box put in the robot's path
  // must not wait for the next tick.
  void OnObstacles(Node& node, const msg::ObstacleArray& m) {
    const std::vector<ObstacleBox> boxes = services::FromObstacles(m);
    bool changed = false;
    const auto why = obstacles_.Update(msg::ToNanoseconds(m.header.stamp), boxes, &changed);
    node.CountRejection("obstacles", why);
    if (why || !changed) return;
    replanner_->SetObstacles(obstacles_.SceneObjects());
    node.SetDiagnosticValue("obstacles", std::to_string(obstacles_.size()));
    node.log().info("{} obstacle(s) in the scene: replanning", obstacles_.size());
    if (active_) Step(node);
  }

  void OnCommand(Node& node, const msg::TaskCommand& m) {
    const int64_t now = msg::ToNanoseconds(msg::Now());
    if (m.command == msg::TaskCommand::CANCEL) {
      if (auto o = replanner_->CancelTask(m.task_id, now)) Publish(node, *o);
      return;
    }
    TaskSpec t;
    t.id = m.task_id;
    t.name = m.task_name;
    t.time_limit = m.time_limit;
    auto refuse = [&](const std::string& reason) {
      TaskOutcome o;
      o.id = m.task_id;
      o.name = m.task_name;
      o.status = TaskStatus::kFailed;
      o.reason = reason;
      Publish(node, o);
    };
    // A repeat of a finished task (the supervisor re-sends while it waits):
    // its outcome again, in case the first one was lost.
    for (const TaskOutcome& done : finished_) {
      if (done.id == m.task_id && done.name == m.task_name) {
        node.log().info("task {} '{}' repeated after it ended: outcome sent again", done.id, done.name);
        Publish(node, done, /*remember=*/false);
        return;
      }
    }
    t.retreat = Eigen::Map<const Eigen::VectorXd>(m.retreat_positions.data(),
                                                  static_cast<Eigen::Index>(m.retreat_positions.size()));
    if (m.goal_type == msg::TaskCommand::GOAL_JOINTS) {
      t.goal = planning::Goal::Joint(Eigen::Map<const Eigen::VectorXd>(m.goal_positions.data(),
                                                                       static_cast<Eigen::Index>(m.goal_positions.size())));
    } else {
      const auto& p = m.goal_pose;
      t.goal = planning::Goal::Pose({p.position.x, p.position.y, p.position.z},
                                    Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
                                        .normalized());
    }
    if (replanner_->current_task_id() == t.id) return;  // a re-sent command of the running task
    std::optional<TaskOutcome> replaced;
    try {
      replaced = replanner_->StartTask(t, now);  // validates everything before replacing the running task
    } catch (const std::invalid_argument& e) {
      refuse(e.what());
      return;
    }
    node.log().info("task {} '{}' started", t.id, t.name);
    if (replaced) Publish(node, *replaced);
  }

  void Publish(Node& node, const TaskOutcome& o, bool remember = true) {
    if (remember) {
      finished_.push_back(o);
      if (finished_.size() > 32) finished_.pop_front();
    }
    msg::TaskOutcome m;
    m.header.stamp = msg::Now();
    m.task_id = o.id;
    m.task_name = o.name;
    m.status = services::ToWire(o.status);
    m.reason = o.reason;
    m.duration = o.duration;
    m.delay = o.delay;
    m.num_waits = o.num_waits;
    m.planning_time_p50 = o.planning_time_p50;
    m.planning_time_p99 = o.planning_time_p99;
    m.max_collision_bound = o.max_collision_bound;
    outcome_writer_->Write(m);
    node.log().info("task {} '{}' {} after {:.2f} s (delay {:.2f} s, {} waits){}{}", o.id, o.name,
                    cell::ToString(o.status), o.duration, o.delay, o.num_waits,
                    o.reason.empty() ? "" : ": ", o.reason);
  }

  void Step(Node& node) {
    const auto t0 = std::chrono::steady_clock::now();
    last_cycle_ = t0;
    const int64_t cycle_start_ns = msg::ToNanoseconds(msg::Now());
    if (obstacles_.Expire(cycle_start_ns)) {
      replanner_->SetObstacles(obstacles_.SceneObjects());
      node.SetDiagnosticValue("obstacles", std::to_string(obstacles_.size()));
      node.log().info("obstacle(s) no longer seen: {} left in the scene", obstacles_.size());
    }
    const CycleResult r = replanner_->Cycle(cycle_start_ns);
    msg::PlanStatus status;
    if (r.publish) {
      const int64_t publish_ns = msg::ToNanoseconds(msg::Now());
      trajectory_writer_->Write(services::ToTrajectory(r.start_ns, replanner_->joint_names(), r.positions, r.dt,
                                                       output_, publish_ns));
      // End-to-end latency: from the observation behind the prediction this
      // plan avoided to the moment the plan is out.
      const int64_t published_ns = msg::ToNanoseconds(msg::Now());
      status.trajectory_stamp = msg::TimeFromNanoseconds(r.start_ns);
      if (r.prediction_t0_ns > 0) {
        status.skeleton_stamp = msg::TimeFromNanoseconds(r.prediction_t0_ns);
        status.latency = std::max(0.0, 1e-9 * static_cast<double>(published_ns - r.prediction_t0_ns));
        // The stages of that latency (perception -> intent -> this cycle -> plan out).
        if (latest_prediction_.first == r.prediction_t0_ns) {
          status.intent_latency = std::max(0.0, 1e-9 * static_cast<double>(latest_prediction_.second - r.prediction_t0_ns));
          status.queue_latency = std::max(0.0, 1e-9 * static_cast<double>(cycle_start_ns - latest_prediction_.second));
          node.SetDiagnosticValue("latency_intent_s", std::to_string(status.intent_latency));
          node.SetDiagnosticValue("latency_queue_s", std::to_string(status.queue_latency));
        }
        node.SetDiagnosticValue("latency_s", std::to_string(status.latency));
      }
    }
    if (r.publish || r.planning_time > 0) {
      status.header.stamp = msg::Now();
      status.planning_time = r.planning_time;
      status.task_id = replanner_->current_task_id().value_or(0);
      status.waiting = r.waiting;
      status.max_bound = std::clamp(r.max_bound, 0.0, 1.0);
      status.status = r.status;
      status_writer_->Write(status);
    }
    if (r.outcome) Publish(node, *r.outcome);
    if (r.status != last_status_) {
      node.log().debug("{}", r.status);
      last_status_ = r.status;
    }
    // Escapes are rare and the integrator's question after a near miss.
    if (const bool escaping = r.status.find("escaping") != std::string::npos; escaping != escaping_) {
      node.log().info("{}{}", escaping ? "" : "no longer escaping: ", r.status);
      escaping_ = escaping;
    }
    node.SetDiagnosticValue("status", r.status);
    if (r.planning_time > 0) node.SetDiagnosticValue("people", std::to_string(r.num_people));
    if (r.budget_exhausted) node.SetDiagnosticValue("budget_exhausted_cycles", std::to_string(++budget_exhausted_));
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }

  services::TrajectoryOutput output_;
  bool escaping_ = false;  // the last cycle's plan was an escape (escape.h)
  double planning_step_ = 0.1;  // s
  bool replan_on_prediction_ = true;
  bool active_ = false;
  std::chrono::steady_clock::time_point last_cycle_{};
  // Observation and publication stamps (ns) of the newest accepted prediction.
  std::pair<int64_t, int64_t> latest_prediction_{0, 0};
  int budget_exhausted_ = 0;    // cycles whose planning ran out of the cycle budget
  bool use_prediction_ = true;
  std::unique_ptr<planning::Planner> planner_;
  std::unique_ptr<collision::HumanBodyModel> body_;
  std::unique_ptr<Replanner> replanner_;
  ObstacleSet obstacles_;  // the boxes of /iplan/obstacles the plans keep clear of
  dds::Writer<msg::JointTrajectory>* trajectory_writer_ = nullptr;
  dds::Writer<msg::TaskOutcome>* outcome_writer_ = nullptr;
  dds::Writer<msg::PlanStatus>* status_writer_ = nullptr;
  std::string last_status_;
  std::deque<TaskOutcome> finished_;  // the last outcomes, answered again on a repeated command
  int timer_ = 0;
};

}  // namespace
}  // namespace iplan::trajopt

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv,
      {"trajopt", "replans the robot trajectory every planning step against the predicted person (ITOMP)"},
      [] { return std::make_unique<iplan::trajopt::TrajoptService>(); });
}
