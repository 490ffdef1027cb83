// iplan-supervisor: the task planner (MDP + Q-learning, METHOD 6) and the
// cell's deadline / liveliness monitor. It issues task commands to the
// trajectory optimiser, learns from their outcomes and the predicted human
// action, and withholds its permit to move (/iplan/safety/permit/supervisor, asserted
// every permit period, not only on change) whenever an input is late, gone
// or unusable or the collision-risk verdict says stop, granting it again
// when all is healthy. While a task runs its command is re-sent every
// command_resend_period, so an outcome lost to a frozen or restarted
// supervisor (or optimiser) is recovered and the cell never idles for good.
#include <chrono>
#include <filesystem>

#include "iplan/adapters/adapters.h"
#include "services/supervisor/core/safety_monitor.h"
#include "services/supervisor/core/supervisor_settings.h"
#include "services/supervisor/core/task_goals.h"
#include "services/supervisor/core/task_planner.h"
#include "iplan/core/params.h"
#include "iplan/framework/service.h"
#include "services/trajopt/trajopt_config.h"

namespace iplan::supervisor {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

// The task graph's places in joint positions of the cell's robot: the
// robot, scene and planner of the trajectory optimiser's file (the robot
// replaced by supervisor.robot when given), as that service plans with them.
std::vector<std::string> ResolveGoals(const ConfigSection& config, const SupervisorSettings& settings,
                                      TaskGraph* graph) {
  const trajopt::TrajoptConfig topt = trajopt::LoadTrajoptConfig(
      config.ResolvePath(settings.trajopt_config), settings.robot.empty() ? "" : config.ResolvePath(settings.robot));
  return ResolveTaskGoals(*trajopt::MakePlanner(topt), graph);
}

class SupervisorService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    SupervisorSettings settings;
    core::ReadParams(config, &settings);  // every range: SupervisorSettings::Validate
    if (settings.watch.empty()) {
      node.log().warn("supervisor.watch is empty: the deadline / liveliness monitor watches nothing");
    }
    QLearningParams q = settings.learning;
    q.learning = settings.mode == "learning";
    deployment_ = settings.mode == "deployment";
    const std::vector<std::string>& watched = settings.watch;
    const std::string graph_file = settings.task_graph;
    const double resume_delay = settings.resume_delay;
    q_table_ = config.ResolvePath(settings.q_table);
    pause_ = settings.pause_between_tasks;
    max_episodes_ = settings.max_episodes;
    permit_period_ = settings.permit_period;
    permit_validity_ = settings.permit_validity;
    resend_period_ = settings.command_resend_period;
    tracker_ = ActionTracker(settings.tracker);
    try {
      TaskGraph graph = LoadTaskGraph(config.ResolvePath(graph_file));
      for (const std::string& note : ResolveGoals(config, settings, &graph)) node.log().info("{}", note);
      planner_ = std::make_unique<TaskPlanner>(std::move(graph), q);
      if (!q_table_.empty()) {
        std::string note;
        planner_->Load(q_table_, &note);
        node.log().info("{}", note);
      }
    } catch (const std::exception& e) {
      return Result::Fail(e.what());
    }
    // Task ids continue from the clock (ms), so a restarted supervisor never
    // reuses the id of a task the optimiser already finished.
    task_id_ = static_cast<uint32_t>((msg::ToNanoseconds(msg::Now()) / 1000000) % 2000000000);
    command_writer_ = &node.Advertise(framework::topics::TaskCommand());
    permit_writer_ = &node.Advertise(framework::topics::SupervisorPermit());
    using SI = const dds::SampleInfo&;
    // Watched topics: any accepted sample is a sign of life; deadline and
    // liveliness events come through OnReaderEvent.
    std::vector<std::string> names;
    for (const std::string& w : watched) {
      if (w == "human_skeleton") Watch(node, framework::topics::HumanSkeleton(), &names);
      else if (w == "human_prediction") Watch(node, framework::topics::HumanPrediction(), &names);
      else if (w == "joint_states") Watch(node, framework::topics::JointStates(), &names);
      else if (w == "robot_trajectory") Watch(node, framework::topics::RobotTrajectory(), &names);
      else if (w == "collision_risk") Watch(node, framework::topics::CollisionRisk(), &names);
      else if (w == "action_belief") Watch(node, framework::topics::ActionBelief(), &names);
      else if (w == "human_points") Watch(node, framework::topics::HumanPoints(), &names);
      else return Result::Fail(config.file() + ": key 'supervisor.watch': unknown topic '" + w +
                               "' (human_skeleton, human_prediction, action_belief, human_points, joint_states, "
                               "robot_trajectory, collision_risk)");
    }
    monitor_ = std::make_unique<SafetyMonitor>(names);
    monitor_->SetResumeDelay(resume_delay);
    for (const auto& [name, deadline] : deadlines_) monitor_->SetDeadline(name, deadline);
    node.OnReaderEvent([this](const std::string& topic, const dds::ReaderEvent& e) {
      if (e.kind == dds::EventKind::kDeadlineMissed) monitor_->OnDeadlineMissed(topic);
      if (e.kind == dds::EventKind::kLivelinessLost) monitor_->OnLivelinessLost(topic, e.current);
    });
    if (std::find(watched.begin(), watched.end(), "action_belief") == watched.end()) {
      node.Subscribe(framework::topics::ActionBelief(),
                     std::function<void(const msg::ActionBelief&, SI)>([this](const msg::ActionBelief& b, SI) { Belief(b); }));
    }
    node.Subscribe(framework::topics::TaskOutcome(),
                   std::function<void(const msg::TaskOutcome&, SI)>([this, &node](const msg::TaskOutcome& o, SI) {
                     OnOutcome(node, o);
                   }),
                   framework::SubscribeOptions{false});
    return Result::Ok();
  }

  Result OnActivate(Node& node) override {
    timer_ = node.AddTimer(std::chrono::milliseconds(20), [this, &node] { Tick(node); });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    node.CancelTimer(timer_);
    return Result::Ok();
  }

  // A deployed cell's safety authority never runs unauthenticated by
  // accident: its permit must be its own (docs/safety.md, "Threat model").
  std::string SecurityRequiredBy() const override { return deployment_ ? "supervisor.mode is deployment" : ""; }

 private:
  template <class T>
  void Watch(Node& node, const framework::Topic<T>& topic, std::vector<std::string>* names) {
    names->push_back(topic.name);
    deadlines_.emplace_back(topic.name, std::chrono::duration<double>(topic.qos.deadline).count());
    const std::string name = topic.name;
    // Only samples that passed every check arrive here: they alone count as
    // signs of life (rejected samples still meet the DDS deadline).
    node.Subscribe(topic, std::function<void(const T&, const dds::SampleInfo&)>([this, name](const T& m, const dds::SampleInfo&) {
                     monitor_->OnData(name, msg::ToNanoseconds(msg::Now()));
                     if constexpr (std::is_same_v<T, msg::CollisionRisk>) {
                       // The boundary refuses octets the IDL does not define; an unknown one would stop.
                       monitor_->OnRiskVerdict(services::VerdictFromWire(m.verdict).value_or(cell::Verdict::kProtectiveStop),
                                               m.reason, m.retreating);
                     }
                     if constexpr (std::is_same_v<T, msg::ActionBelief>) Belief(m);
                   }));
  }

  void Belief(const msg::ActionBelief& b) {
    belief_.clear();
    for (std::size_t i = 0; i < b.actions.size(); ++i) belief_[b.actions[i]] = b.probabilities[i];
    // How long the person has been at it, in the skeletons' time (the
    // stamp of the observation the belief was computed from).
    belief_at_ = msg::ToSeconds(b.observation_stamp);
    tracker_.Update(belief_at_, belief_);
  }

  void PublishPermit(const SafetyDecision& d) {
    msg::SafetyPermit p;
    p.header.stamp = msg::Now();
    p.seq = ++permit_seq_;
    p.state = d.stop ? msg::SafetyPermit::STOP : msg::SafetyPermit::PERMIT;
    p.validity = permit_validity_;
    p.source = "supervisor";
    p.reason = d.reason;
    permit_writer_->Write(p);
    last_permit_at_ = std::chrono::steady_clock::now();
  }

  void Tick(Node& node) {
    bool changed = false;
    const SafetyDecision d = monitor_->Evaluate(&changed, msg::ToNanoseconds(msg::Now()));
    // Asserted every period whatever the state, at once on a change.
    const auto now_steady = std::chrono::steady_clock::now();
    if (changed || now_steady - last_permit_at_ >= std::chrono::duration<double>(permit_period_)) PublishPermit(d);
    if (changed) {
      if (d.stop) {
        ++stops_;
        node.log().warn("PROTECTIVE STOP: {}", d.reason);
      } else {
        node.log().info("RESUME: {}", d.reason);
        // A restarted trajectory optimiser never saw the running task's
        // (volatile) command: send it again; the optimiser ignores a repeat.
        if (current_task_ >= 0) ResendCommand();
      }
      node.SetDiagnosticValue("safety", d.stop ? "stopped: " + d.reason : "running");
      node.SetDiagnosticValue("protective_stops", std::to_string(stops_));
    }
    // A running task's command again every resend period: the optimiser
    // ignores a repeat of its running task and answers a repeat of a
    // finished one with its outcome again (one lost to a freeze).
    if (current_task_ >= 0 && now_steady - last_command_at_ >= std::chrono::duration<double>(resend_period_)) {
      ResendCommand();
    }
    // Issue the next task when idle (tasks are not started while stopped).
    if (d.stop || current_task_ >= 0) return;
    if (max_episodes_ > 0 && episodes_ >= max_episodes_) return;
    if (std::chrono::steady_clock::now() < next_task_at_) return;
    if (planner_->episode_done()) {
      ++episodes_;
      node.log().info("episode {} done", episodes_);
      node.SetDiagnosticValue("episodes", std::to_string(episodes_));
      planner_->ResetEpisode();
      if (max_episodes_ > 0 && episodes_ >= max_episodes_) return;
    }
    // The anticipating choice (docs/supervisor.md): the belief and how long
    // its action has lasted, as of the newest belief.
    const ActionOutlook outlook = tracker_.Outlook(belief_, belief_at_);
    current_task_ = planner_->Choose(outlook);
    if (current_task_ < 0) return;
    const RobotTask& t = planner_->graph().tasks[static_cast<std::size_t>(current_task_)];
    msg::TaskCommand& c = command_;
    c.header.stamp = msg::Now();
    c.task_id = ++task_id_;
    c.task_name = t.name;
    c.command = msg::TaskCommand::START;
    c.goal_type = msg::TaskCommand::GOAL_JOINTS;
    c.goal_positions = t.goal;
    c.retreat_positions = t.retreat;
    c.episode = static_cast<uint32_t>(episodes_ + 1);
    command_writer_->Write(c);
    last_command_at_ = std::chrono::steady_clock::now();
    node.log().info("task {} '{}' (episode {}, state {:#x}, epsilon {:.3f}; expected conflict {:.2f} s of {:.2f} s, "
                    "person: {} for {}{:.1f} s)",
                    task_id_, t.name, episodes_ + 1, planner_->state(), planner_->Epsilon(),
                    planner_->ExpectedConflict(current_task_, outlook), planner_->TaskDuration(current_task_),
                    tracker_.action().empty() ? "unknown" : tracker_.action(), outlook.elapsed_at_least ? "at least " : "",
                    outlook.elapsed);
  }

  void ResendCommand() {
    command_.header.stamp = msg::Now();
    command_writer_->Write(command_);
    last_command_at_ = std::chrono::steady_clock::now();
  }

  void OnOutcome(Node& node, const msg::TaskOutcome& o) {
    if (current_task_ < 0 || o.task_id != task_id_) return;  // not ours / stale
    const bool ok = services::TaskStatusFromWire(o.status) == cell::TaskStatus::kSucceeded;
    // Its time without the delay: how long it takes when nothing is in the way.
    const double reward = planner_->Complete(current_task_, ok, o.delay, belief_, o.duration - o.delay);
    ++completed_;
    node.log().info("task {} '{}' {} in {:.2f} s, delay {:.2f} s, reward {:.3f}", o.task_id, o.task_name,
                    ok ? "succeeded" : "failed", o.duration, o.delay, reward);
    current_task_ = -1;
    next_task_at_ = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int64_t>(pause_ * 1000));
    node.SetDiagnosticValue("tasks_completed", std::to_string(completed_));
    node.SetDiagnosticValue("last_reward", std::to_string(reward));
    node.SetDiagnosticValue("episodes_learned", std::to_string(planner_->episodes_learned()));
    node.SetDiagnosticValue("epsilon", std::to_string(planner_->Epsilon()));
    if (!q_table_.empty()) {
      try {
        planner_->Save(q_table_);
      } catch (const std::exception& e) {
        node.log().error("Q-table not saved: {}", e.what());
        node.SetDiagnosticValue("q_table_last_save_error", planner_->last_save_error());
      }
      node.SetDiagnosticValue("q_table_save_failures", std::to_string(planner_->save_failures()));
      node.SetDiagnosticValue("refused_outcomes", std::to_string(planner_->refused_outcomes()));
    }
  }

  std::unique_ptr<TaskPlanner> planner_;
  std::unique_ptr<SafetyMonitor> monitor_;
  std::string q_table_ = "state/q_table.bin";
  double pause_ = 0.5;
  int max_episodes_ = 0;
  dds::Writer<msg::TaskCommand>* command_writer_ = nullptr;
  bool deployment_ = false;  // supervisor.mode deployment: needs DDS Security
  dds::Writer<msg::SafetyPermit>* permit_writer_ = nullptr;
  double permit_period_ = 0.05, permit_validity_ = 0.2, resend_period_ = 1.0;  // s
  std::vector<std::pair<std::string, double>> deadlines_;  // watched topic, s
  std::chrono::steady_clock::time_point last_permit_at_{}, last_command_at_{};
  std::map<std::string, double> belief_;
  double belief_at_ = 0;  // s, observation stamp of the newest belief
  ActionTracker tracker_;
  msg::TaskCommand command_;  // the running task's command (re-sent on resume)
  int current_task_ = -1;
  uint32_t task_id_ = 0, permit_seq_ = 0;
  int episodes_ = 0;
  uint64_t completed_ = 0, stops_ = 0;
  std::chrono::steady_clock::time_point next_task_at_{};
  int timer_ = 0;
};

}  // namespace
}  // namespace iplan::supervisor

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv,
      {"supervisor", "task planning (MDP + Q-learning) and the deadline / liveliness monitor that stops the robot"},
      [] { return std::make_unique<iplan::supervisor::SupervisorService>(); });
}
