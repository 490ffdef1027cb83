// iplan-collision-risk: the independent watchdog on the executing trajectory.
// Evaluates the collision bound against every human prediction and ISO/TS
// 15066 separation monitoring, and publishes /iplan/collision_risk.
#include <chrono>
#include <filesystem>

#include "common/adapters.h"
#include "core/risk_monitor.h"
#include "iplan/framework/service.h"

namespace iplan::collision_risk {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class CollisionRiskService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    std::string robot_file = "robots/panda.yaml", body_file = "humans/upper_body.yaml";
    config.Read("robot", &robot_file);
    config.Read("human_body", &body_file);
    config.Read("rate_hz", &rate_hz_, framework::InRange(1.0, 1000.0));
    config.Read("delta_cl", &params_.delta_cl, framework::Check<double>([](const double& v) {
                  return v > 0 && v < 1 ? std::string() : std::string("must be in (0, 1)");
                }));
    config.Read("stop_horizon", &params_.stop_horizon, framework::NonNegative<double>());
    config.Read("slow_down_fraction", &params_.slow_down_fraction, framework::InRange(0.01, 1.0));
    config.Read("slow_down_margin", &params_.slow_down_margin, framework::NonNegative<double>());
    config.Read("stale_after", &params_.stale_after, framework::Positive<double>());
    ConfigSection iso = config.Section("iso_ts_15066");
    SsmParams& s = params_.ssm;
    iso.Read("measure_human_speed", &s.measure_human_speed);
    iso.Read("default_human_speed", &s.default_human_speed, framework::NonNegative<double>());
    iso.Read("speed_window", &s.speed_window, framework::Positive<double>());
    iso.Read("reaction_time", &s.reaction_time, framework::NonNegative<double>());
    iso.Read("stopping_time", &s.stopping_time, framework::NonNegative<double>());
    iso.Read("stopping_distance", &s.stopping_distance, framework::NonNegative<double>());
    iso.Read("intrusion_distance", &s.intrusion_distance, framework::NonNegative<double>());
    iso.Read("sensing_uncertainty", &s.sensing_uncertainty, framework::NonNegative<double>());
    iso.Read("robot_uncertainty", &s.robot_uncertainty, framework::NonNegative<double>());
    if (const std::string why = params_.Validate(); !why.empty()) return Result::Fail(config.file() + ": " + why);
    try {
      const std::string robot_path = config.ResolvePath(robot_file);
      const std::string body_path = config.ResolvePath(body_file);
      monitor_ = std::make_unique<RiskMonitor>(collision::LoadRobotModelFromYaml(robot_path),
                                               collision::LoadHumanBodyParams(body_path), params_);
      node.log().info("robot {} ({} spheres), human body {} ({} spheres)", robot_path,
                      monitor_->robot().spheres.size(), body_path, monitor_->body().num_spheres());
    } catch (const std::exception& e) {
      return Result::Fail(e.what());
    }
    writer_ = &node.Advertise(framework::topics::CollisionRisk());
    using SI = const dds::SampleInfo&;
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, SI)>([this, &node](const msg::JointState& m, SI) {
                     node.CountRejection("joint_states", monitor_->UpdateRobotState(msg::ToNanoseconds(m.header.stamp), m.name, m.position));
                   }));
    node.Subscribe(framework::topics::RobotTrajectory(),
                   std::function<void(const msg::JointTrajectory&, SI)>([this, &node](const msg::JointTrajectory& m, SI) {
                     std::vector<double> times;
                     std::vector<std::vector<double>> pos;
                     services::FromTrajectory(m, &times, &pos);
                     node.CountRejection("trajectory", monitor_->UpdateTrajectory(msg::ToNanoseconds(m.header.stamp), m.joint_names, times, pos));
                   }));
    node.Subscribe(framework::topics::HumanSkeleton(),
                   std::function<void(const msg::HumanSkeleton&, SI)>([this, &node](const msg::HumanSkeleton& m, SI) {
                     std::vector<std::string> names;
                     std::vector<Eigen::Vector3d> p;
                     for (const auto& j : m.joints) {
                       names.push_back(j.name);
                       p.emplace_back(j.position.x, j.position.y, j.position.z);
                     }
                     node.CountRejection("skeleton", monitor_->UpdateSkeleton(msg::ToNanoseconds(m.header.stamp), names, p));
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
  void OnPrediction(Node& node, const msg::HumanPrediction& m) {
    const PredictionInput in = services::ToJointMixture(m);
    const auto rejection = monitor_->UpdatePrediction(in);
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
    m.min_separation = r.min_separation;
    m.protective_separation = r.protective_separation;
    m.human_speed = r.human_speed;
    m.robot_speed = r.robot_speed;
    m.verdict = static_cast<uint8_t>(r.verdict);
    m.reason = r.reason;
    writer_->Write(m);
    last_publish_ns_ = now_ns;
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (r.verdict != last_verdict_) {
      static const char* kNames[] = {"OK", "SLOW_DOWN", "PROTECTIVE_STOP"};
      node.log().info("verdict {}: {}", kNames[static_cast<int>(r.verdict)], r.reason);
      last_verdict_ = r.verdict;
    }
  }

  RiskParams params_;
  double rate_hz_ = 15;
  std::unique_ptr<RiskMonitor> monitor_;
  dds::Writer<msg::CollisionRisk>* writer_ = nullptr;
  int timer_ = 0;
  int64_t last_publish_ns_ = 0;
  Verdict last_verdict_ = Verdict::kOk;
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
