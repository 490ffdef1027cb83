// iplan demo's view of the running cell: a monitoring participant that
// follows task commands and outcomes, plan statuses, collision-risk verdicts,
// both monitors' permits and every service's diagnostics, and keeps what the
// demo's progress line and summary show (episodes, stops and slow-downs,
// separation, bound, latency), and with a TrueSeparationJudge audits each
// stop against the true person (stop_audit.h). Single-threaded: its
// callbacks run on the node's thread (Node::SpinOnce).
#pragma once

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "episode_tally.h"
#include "fixed_text.h"
#include "iplan/adapters/adapters.h"
#include "iplan/framework/node.h"
#include "iplan/framework/topics.h"
#include "stop_audit.h"

namespace iplan::cli {

class CellMonitor {
 public:
  using Clock = std::chrono::steady_clock;
  CellMonitor(framework::Node& node, int num_tasks, Clock::time_point t0) : tally_(num_tasks), t0_(t0) {
    using SI = const dds::SampleInfo&;
    namespace topics = framework::topics;
    const framework::SubscribeOptions any_order{false};
    node.Subscribe(topics::TaskCommand(), std::function<void(const msg::TaskCommand&, SI)>(
                                              [this](const msg::TaskCommand& m, SI) { OnCommand(m); }),
                   any_order);
    node.Subscribe(topics::TaskOutcome(), std::function<void(const msg::TaskOutcome&, SI)>(
                                              [this](const msg::TaskOutcome& m, SI) { OnOutcome(m); }),
                   any_order);
    node.Subscribe(topics::PlanStatus(), std::function<void(const msg::PlanStatus&, SI)>([this](const msg::PlanStatus& m, SI) {
                     if (m.latency > 0) {
                       latency_ms_.push_back(1e3 * m.latency);
                       intent_ms_.push_back(1e3 * m.intent_latency);
                       queue_ms_.push_back(1e3 * m.queue_latency);
                       planning_ms_.push_back(1e3 * m.planning_time);
                     }
                     waiting_ = m.waiting;
                     max_plan_bound_ = std::max(max_plan_bound_, m.max_bound);
                   }));
    node.Subscribe(topics::CollisionRisk(),
                   std::function<void(const msg::CollisionRisk&, SI)>([this](const msg::CollisionRisk& m, SI) {
                     max_bound_ = std::max(max_bound_, m.max_bound);
                     const bool slowed = m.verdict == msg::CollisionRisk::SLOW_DOWN && m.speed_scale < 1.0;
                     if (std::exchange(slowed_, slowed) != slowed && slowed) ++slow_downs_;  // speed reduction
                     separation_ = m.min_separation;
                     min_observed_separation_ = std::min(min_observed_separation_, m.min_separation);
                   }));
    // The robot is stopped while any monitor withholds its permit; a stop
    // is counted when the first one does.
    for (const auto& topic : {topics::SupervisorPermit(), topics::CollisionRiskPermit()}) {
      node.Subscribe(topic, std::function<void(const msg::SafetyPermit&, SI)>([this](const msg::SafetyPermit& m, SI) {
                       const bool was_stopped = stopped_;
                       permit_stops_[m.source] = m.state == msg::SafetyPermit::STOP;
                       stopped_ = std::any_of(permit_stops_.begin(), permit_stops_.end(), [](const auto& p) { return p.second; });
                       if (stopped_ && !was_stopped) {
                         ++stops_;
                         stop_reasons_.push_back(m.source + ": " + m.reason);
                         stop_since_ = Now();
                         audit_.StopStarted(stop_since_, stop_reasons_.back());
                       }
                       if (!stopped_ && was_stopped) {
                         stop_time_s_ += Now() - stop_since_;
                         audit_.StopEnded(Now());
                       }
                     }),
                     any_order);
    }
    node.Subscribe(topics::Diagnostics(),
                   std::function<void(const msg::DiagnosticArray& a, SI)>([this](const msg::DiagnosticArray& a, SI) {
                     for (const auto& st : a.status) {
                       for (const auto& kv : st.values) diag_[st.name][kv.key] = kv.value;
                     }
                   }),
                   any_order);
  }

  // Judges every true pose of the simulated person against the robot's
  // state and executing trajectory, so that each stop is timed against the
  // true person's stay within S_p (stop_audit()).
  void AuditStops(framework::Node& node, std::unique_ptr<TrueSeparationJudge> judge) {
    using SI = const dds::SampleInfo&;
    namespace topics = framework::topics;
    judge_ = std::move(judge);
    node.Subscribe(topics::JointStates(), std::function<void(const msg::JointState&, SI)>([this](const msg::JointState& m, SI) {
                     judge_->UpdateRobotState(msg::ToNanoseconds(m.header.stamp), m.name, m.position);
                   }));
    node.Subscribe(topics::RobotTrajectory(),
                   std::function<void(const msg::JointTrajectory&, SI)>([this](const msg::JointTrajectory& m, SI info) {
                     std::vector<double> times;
                     std::vector<std::vector<double>> pos;
                     services::FromTrajectory(m, &times, &pos);
                     judge_->UpdateTrajectory(services::TrajectoryStartNs(m, info.reception_ns), m.joint_names, times, pos);
                   }));
    node.Subscribe(topics::HumanTruth(), std::function<void(const msg::HumanSkeleton&, SI)>([this](const msg::HumanSkeleton& m, SI) {
                     std::vector<std::string> names;
                     std::vector<Eigen::Vector3d> p;
                     for (const auto& j : m.joints) {
                       names.push_back(j.name);
                       p.emplace_back(j.position.x, j.position.y, j.position.z);
                     }
                     if (judge_->UpdateTruth(msg::ToNanoseconds(m.header.stamp), names, p)) return;
                     if (const std::optional<bool> inside = judge_->Inside(msg::ToNanoseconds(msg::Now())))
                       audit_.Judge(Now(), *inside);
                   }));
  }
  const StopAudit& stop_audit() const { return audit_; }
  bool auditing_stops() const { return judge_ != nullptr; }
  /// s since the demo started of the first task command (the stops before
  /// it are the cell's safe start); infinity before it.
  double first_task_s() const { return tally_.first_task_s(); }

  double Now() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }
  const EpisodeTally& tally() const { return tally_; }
  const std::map<int, Episode>& episodes() const { return tally_.episodes(); }
  int completed_episodes() const { return tally_.completed_episodes(); }
  std::string Diag(const std::string& service, const std::string& key, const std::string& otherwise = "") const {
    auto s = diag_.find(service);
    if (s == diag_.end()) return otherwise;
    auto k = s->second.find(key);
    return k == s->second.end() ? otherwise : k->second;
  }
  double DiagNumber(const std::string& service, const std::string& key, double otherwise) const {
    const std::string v = Diag(service, key);
    try {
      return v.empty() ? otherwise : std::stod(v);
    } catch (...) {
      return otherwise;
    }
  }

  // The progress line.
  std::string Progress(int total_episodes) const {
    std::ostringstream s;
    const int e = tally_.current_episode();
    s << "  [" << std::setw(4) << Fixed(Now(), 0) << " s] ";
    if (e == 0) {
      s << "waiting for the cell (supervisor: " << Diag("supervisor", "safety", "starting") << ")";
    } else {
      s << "episode " << e << "/" << total_episodes << ": " << (tally_.current_task().empty() ? "-" : tally_.current_task())
        << (waiting_ ? " (waiting)" : "");
    }
    s << " | person: " << Diag("perception", "action", "?") << " | separation "
      << (separation_ < 1e9 ? Fixed(separation_, 2) + " m" : "-") << " | bound " << Fixed(max_bound_, 3)
      << " | stops " << stops_ << " | contacts " << Diag("robot_sim", "true_contacts", "0");
    return s.str();
  }

  std::vector<std::string> TakeEvents() { return std::exchange(events_, {}); }

  std::vector<double> latency_ms_;
  // Its stages, per trajectory: skeleton to prediction (intent), prediction
  // to the planning cycle's start (DDS and waiting), the cycle's planning.
  std::vector<double> intent_ms_, queue_ms_, planning_ms_;
  double max_bound_ = 0, max_plan_bound_ = 0;
  double separation_ = 1e18, min_observed_separation_ = 1e18;
  uint64_t stops_ = 0, slow_downs_ = 0;
  bool slowed_ = false;  // the last verdict slowed the robot
  double stop_since_ = 0, stop_time_s_ = 0;  // s since the demo started; s stopped (ended stops)
  std::vector<std::string> stop_reasons_;

 private:
  void OnCommand(const msg::TaskCommand& m) {
    if (m.command != msg::TaskCommand::START) return;
    tally_.Started(m.task_id, static_cast<int>(m.episode), m.task_name, Now());
  }
  void OnOutcome(const msg::TaskOutcome& m) {
    const EpisodeTally::Ending ending = m.status == msg::TaskOutcome::SUCCEEDED ? EpisodeTally::Ending::kSucceeded
                                        : m.status == msg::TaskOutcome::FAILED  ? EpisodeTally::Ending::kFailed
                                                                                : EpisodeTally::Ending::kCancelled;
    for (std::string& e : tally_.Ended(m.task_id, ending, m.task_name, m.delay, m.reason, Now()))
      events_.push_back(std::move(e));
  }

  EpisodeTally tally_;
  Clock::time_point t0_;
  bool waiting_ = false, stopped_ = false;
  std::map<std::string, bool> permit_stops_;  // per monitor: its last permit is a STOP
  std::map<std::string, std::map<std::string, std::string>> diag_;
  std::vector<std::string> events_;
  std::unique_ptr<TrueSeparationJudge> judge_;  // null: stops not audited
  StopAudit audit_;
};

}  // namespace iplan::cli
