// iplan-collision-risk: the independent watchdog on the executing trajectory.
// Evaluates the collision bound against every human prediction and ISO/TS
// 15066 separation monitoring, publishes /iplan/collision_risk, and with
// every evaluation its own permit to move (/iplan/safety/permit/collision_risk): the robot
// obeys it independently of the supervisor, so the robot stops when this
// service stops evaluating, whatever happens to the supervisor.
#include <chrono>
#include <filesystem>

#include "iplan/adapters/adapters.h"
#include "services/collision_risk/core/risk_monitor.h"
#include "risk_config.h"
#include "iplan/framework/service.h"

namespace iplan::collision_risk {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class CollisionRiskService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    const RiskConfig rc = ReadRiskConfig(config);
    params_ = rc.params;
    rate_hz_ = rc.rate_hz;
    permit_validity_ = rc.permit_validity;
    if (!config.Problems().empty()) return Result::Ok();  // reported by the configuration check
    try {
      monitor_ = std::make_unique<RiskMonitor>(MakeRiskMonitor(rc));
      node.log().info("robot {} ({} spheres), human body {} ({} spheres)", rc.robot_file,
                      monitor_->robot().spheres.size(), rc.human_body_file, monitor_->body().num_spheres());
    } catch (const std::exception& e) {
      return Result::Fail(e.what());
    }
    writer_ = &node.Advertise(framework::topics::CollisionRisk());
    permit_writer_ = &node.Advertise(framework::topics::CollisionRiskPermit());
    using SI = const dds::SampleInfo&;
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, SI)>([this, &node](const msg::JointState& m, SI) {
                     node.CountRejection("joint_states", monitor_->UpdateRobotState(msg::ToNanoseconds(m.header.stamp), m.name, m.position));
                   }));
    node.Subscribe(framework::topics::RobotTrajectory(),
                   std::function<void(const msg::JointTrajectory&, SI)>([this, &node](const msg::JointTrajectory& m, SI info) {
                     std::vector<double> times;
                     std::vector<std::vector<double>> pos;
                     services::FromTrajectory(m, &times, &pos);
                     node.CountRejection("trajectory", monitor_->UpdateTrajectory(services::TrajectoryStartNs(m, info.reception_ns),
                                                                                 m.joint_names, times, pos));
                   }));
    node.Subscribe(framework::topics::HumanSkeleton(),
                   std::function<void(const msg::HumanSkeleton&, SI)>([this, &node](const msg::HumanSkeleton& m, SI) {
                     std::vector<std::string> names;
                     std::vector<Eigen::Vector3d> p;
                     for (const auto& j : m.joints) {
                       names.push_back(j.name);
                       p.emplace_back(j.position.x, j.position.y, j.position.z);
                     }
                     node.CountRejection("skeleton", monitor_->UpdateSkeleton(m.body_id, msg::ToNanoseconds(m.header.stamp), names, p));
                   }));
    node.Subscribe(framework::topics::HumanPoints(),
                   std::function<void(const msg::HumanPoints&, SI)>([this, &node](const msg::HumanPoints& m, SI) {
                     OnHumanPoints(node, m);
                   }));
    node.Subscribe(framework::topics::HumanPrediction(),
                   std::function<void(const msg::HumanPrediction&, SI)>([this, &node](const msg::HumanPrediction& m, SI) {
                     OnPrediction(node, m);
                   }));
    return Result::Ok();
  }

  Result OnActivate(Node& node) override {
    // Between predictions (or without any), evaluate at rate_hz so the
    // separation layer keeps watching.
    timer_ = node.AddTimer(std::chrono::nanoseconds(static_cast<int64_t>(1e9 / rate_hz_)), [this, &node] {
      const int64_t now = msg::ToNanoseconds(msg::Now());
      if (now - last_publish_ns_ >= static_cast<int64_t>(0.9e9 / rate_hz_)) Publish(node, now);
    });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    node.CancelTimer(timer_);
    return Result::Ok();
  }

 private:
  // The depth camera's view of the person (stands in for the skeleton and
  // the prediction while they are missing: core/risk_points.cc).
  void OnHumanPoints(Node& node, const msg::HumanPoints& m) {
    node.CountRejection("human_points", monitor_->UpdateHumanPoints(services::FromHumanPoints(m)));
  }

  void OnPrediction(Node& node, const msg::HumanPrediction& m) {
    const PredictionInput in = services::ToJointMixture(m);
    const auto rejection = monitor_->UpdatePrediction(m.body_id, in);
    node.CountRejection("prediction", rejection);
    if (!rejection) Publish(node, msg::ToNanoseconds(msg::Now()));
  }

  void Publish(Node& node, int64_t now_ns) {
    const auto start = std::chrono::steady_clock::now();
    const RiskReport r = monitor_->Evaluate(now_ns);
    msg::CollisionRisk m;
    m.header.stamp = msg::TimeFromNanoseconds(r.stamp_ns);
    m.header.frame_id = "world";
    m.trajectory_stamp = msg::TimeFromNanoseconds(r.trajectory_stamp_ns);
    m.prediction_stamp = msg::TimeFromNanoseconds(r.prediction_stamp_ns);
    m.time_step = r.time_step;
    m.waypoint_bounds = r.waypoint_bounds;
    m.max_bound = r.max_bound;
    m.max_waypoint = static_cast<uint32_t>(r.max_waypoint);
    m.max_time = r.max_time;
    m.max_robot_link = r.max_robot_link;
    m.max_human_segment = r.max_human_segment;
    m.max_action = r.max_action;
    m.min_separation = services::ToWire(r.min_separation);
    m.protective_separation = r.protective_separation;
    m.human_speed = r.human_speed;
    m.robot_speed = r.robot_speed;
    m.separation_margin = services::ToWire(r.separation_margin);
    m.speed_scale = r.speed_scale;
    m.verdict = services::ToWire(r.verdict);
    m.reason = r.reason;
    m.retreating = r.retreating;
    writer_->Write(m);
    msg::SafetyPermit p;
    p.header.stamp = msg::Now();
    p.seq = ++permit_seq_;
    p.state = r.verdict == Verdict::kProtectiveStop ? msg::SafetyPermit::STOP : msg::SafetyPermit::PERMIT;
    p.validity = permit_validity_;
    p.source = "collision_risk";
    p.reason = r.reason;
    p.speed_reduction = 1.0 - r.speed_scale;
    permit_writer_->Write(p);
    last_publish_ns_ = now_ns;
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (r.num_people != last_people_ || r.num_predicted != last_predicted_) {
      last_people_ = r.num_people;
      last_predicted_ = r.num_predicted;
      node.SetDiagnosticValue("people", std::to_string(r.num_people) + " seen, " + std::to_string(r.num_predicted) +
                                            " predicted");
    }
    if (r.verdict != last_verdict_ || r.retreating != last_retreating_) {
      node.log().info("verdict {}{}: {}", ToString(r.verdict), r.retreating ? " (retreating)" : "", r.reason);
      last_verdict_ = r.verdict;
      last_retreating_ = r.retreating;
    }
  }

  RiskParams params_;
  bool last_retreating_ = false;
  double rate_hz_ = 15;
  std::unique_ptr<RiskMonitor> monitor_;
  dds::Writer<msg::CollisionRisk>* writer_ = nullptr;
  dds::Writer<msg::SafetyPermit>* permit_writer_ = nullptr;
  double permit_validity_ = 0.2;  // s
  uint32_t permit_seq_ = 0;
  int timer_ = 0;
  int64_t last_publish_ns_ = 0;
  Verdict last_verdict_ = Verdict::kOk;
  int last_people_ = -1, last_predicted_ = -1;  // persons in the last evaluation (diagnostics)
};

}  // namespace
}  // namespace iplan::collision_risk

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv,
      {"collision_risk", "bounds the probability that the executing trajectory meets the predicted person, "
                         "and watches ISO/TS 15066 separation"},
      [] { return std::make_unique<iplan::collision_risk::CollisionRiskService>(); });
}
