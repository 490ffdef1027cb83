// iplan-robot-sim: a simulated robot for the demo cell and the tests.
// Follows /iplan/robot/trajectory, publishes /joint_states, moves only while
// it holds a fresh permit from every configured monitor
// (/iplan/safety/permit/<monitor>, iplan/safety/permit_gate.h), and counts true
// contacts with the simulated person's true body (/iplan/sim/human_truth).
// Publishes world -> robot base on /tf_static for RViz and Foxglove.
#include <chrono>
#include <filesystem>

#include "iplan/adapters/adapters.h"
#include "services/robot_sim/core/robot_simulator.h"
#include "services/robot_sim/core/robot_sim_settings.h"
#include "iplan/core/params.h"
#include "iplan/framework/service.h"
#include "iplan/safety/permit_gate.h"

namespace iplan::robot_sim {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class RobotSimService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    RobotSimSettings settings;
    core::ReadParams(config, &settings);  // every range: RobotSimSettings::Validate
    // Invalid settings are a configuration problem (recorded above), not something to build from.
    if (const std::string why = settings.Validate(); !why.empty()) return Result::Fail(why);
    control_rate_hz_ = settings.control_rate_hz;
    publish_rate_hz_ = settings.publish_rate_hz;
    const std::string robot_file = settings.robot, body_file = settings.human_body;
    const std::vector<double>& q0 = settings.initial_positions;
    const SimulatorParams& params = settings.simulator;
    const safety::PermitGateParams& permits = settings.permits;
    gate_ = std::make_unique<safety::PermitGate>(permits);
    try {
      auto robot = collision::LoadRobotModel(config.ResolvePath(robot_file));
      sim_ = std::make_unique<RobotSimulator>(std::move(robot), Eigen::Map<const Eigen::VectorXd>(q0.data(), static_cast<Eigen::Index>(q0.size())), params);
      body_ = std::make_unique<collision::HumanBodyModel>(
          collision::LoadHumanBodyParams(config.ResolvePath(body_file)));
    } catch (const std::exception& e) {
      return Result::Fail(e.what());
    }
    joint_writer_ = &node.Advertise(framework::topics::JointStates());
    tf_writer_ = &node.Advertise(framework::topics::TfStatic());
    using SI = const dds::SampleInfo&;
    node.Subscribe(framework::topics::RobotTrajectory(),
                   std::function<void(const msg::JointTrajectory&, SI)>([this, &node](const msg::JointTrajectory& m, SI info) {
                     std::vector<double> times;
                     std::vector<std::vector<double>> pos;
                     services::FromTrajectory(m, &times, &pos);
                     node.CountRejection("trajectory", sim_->SetTrajectory(services::TrajectoryStartNs(m, info.reception_ns),
                                                                           m.joint_names, times, pos));
                   }));
    // Each monitor's permits come on its own topic, from its own writer
    // only (with DDS Security: its enclave alone may publish there), so the
    // topic names the monitor, whatever the sample claims. The writer's
    // identity (info.writer_id) lets the gate hold a stop against another
    // writer's permits and catch two writers claiming one monitor.
    for (const std::string& monitor : permits.monitors) {
      framework::Topic<msg::SafetyPermit> topic;
      try {
        topic = framework::topics::SafetyPermit(monitor);
      } catch (const std::exception& e) {
        return Result::Fail(std::string("permits.monitors: ") + e.what());
      }
      node.Subscribe(topic, std::function<void(const msg::SafetyPermit&, SI)>([this, &node, monitor](const msg::SafetyPermit& m, SI info) {
                       node.CountRejection("permit", gate_->OnPermit(monitor, info.writer_id, m.state == msg::SafetyPermit::PERMIT,
                                                                     m.validity, m.reason, msg::ToNanoseconds(m.header.stamp),
                                                                     msg::ToNanoseconds(msg::Now()), m.speed_reduction));
                     }));
    }
    // A monitor that vanishes (crash, freeze, network) sends no more permits:
    // its last one lapses within its validity, which is shorter than the
    // liveliness lease. Liveliness events are not used: they do not say
    // whose writer was lost, and a stranger's writer must not stop the robot.
    node.Subscribe(framework::topics::HumanTruth(),
                   std::function<void(const msg::HumanSkeleton&, SI)>([this, &node](const msg::HumanSkeleton& m, SI) {
                     Eigen::Matrix3Xd joints(3, body_->num_joints());
                     for (int j = 0; j < body_->num_joints(); ++j) {
                       const std::string& name = body_->params().joints[static_cast<std::size_t>(j)];
                       const auto it = std::find_if(m.joints.begin(), m.joints.end(), [&](const msg::HumanJoint& h) { return h.name == name; });
                       if (it == m.joints.end()) return;  // not this body model's joints
                       joints.col(j) << it->position.x, it->position.y, it->position.z;
                     }
                     const int before = sim_->contacts();
                     sim_->UpdateContacts(joints, *body_);
                     if (sim_->contacts() > before) node.log().error("TRUE CONTACT with the person (#{})", sim_->contacts());
                   }));
    return Result::Ok();
  }

  Result OnActivate(Node& node) override {
    PublishStaticTransform(node);
    last_ = msg::ToNanoseconds(msg::Now());
    const auto period = std::chrono::nanoseconds(static_cast<int64_t>(1e9 / control_rate_hz_));
    const int publish_every = std::max(1, static_cast<int>(std::lround(control_rate_hz_ / publish_rate_hz_)));
    timer_ = node.AddTimer(period, [this, &node, publish_every] {
      const auto t0 = std::chrono::steady_clock::now();
      const int64_t now = msg::ToNanoseconds(msg::Now());
      ApplyPermits(node, now);
      sim_->Step(now, (now - last_) * 1e-9);
      last_ = now;
      if (++steps_ % publish_every == 0) {
        msg::JointState js;
        js.header.stamp = msg::TimeFromNanoseconds(now);
        js.name = sim_->joint_names();
        js.position.assign(sim_->q().data(), sim_->q().data() + sim_->q().size());
        js.velocity.assign(sim_->qd().data(), sim_->qd().data() + sim_->qd().size());
        joint_writer_->Write(js);
        node.SetDiagnosticValue("true_contacts", std::to_string(sim_->contacts()));
        // Absent until the true person has been seen.
        if (const auto& sep = sim_->min_separation_seen())
          node.SetDiagnosticValue("min_true_separation_m", std::to_string(*sep));
        node.SetDiagnosticValue("protective_stops", std::to_string(stops_));
        node.SetDiagnosticValue("speed_scale", std::to_string(sim_->speed_scale()));
        node.SetDiagnosticValue("slowed_down_s", std::to_string(slowed_s_));
        node.SetDiagnosticValue("stopped", sim_->stopped() ? "true" : "false");
        node.SetDiagnosticValue("permit", permit_reason_);
        node.SetDiagnosticValue("permit_writer_conflicts", std::to_string(writer_conflicts_));
        if (!writer_conflict_.empty()) node.SetDiagnosticValue("permit_writer_conflict", writer_conflict_);
        node.SetDiagnosticValue("last_stopping_distance_m", std::to_string(sim_->last_stopping_distance()));
      }
      node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    node.CancelTimer(timer_);
    const auto& sep = sim_->min_separation_seen();
    node.log().info("true contacts {}, minimum true separation {}, protective stops {}", sim_->contacts(),
                    sep ? std::to_string(*sep) + " m" : std::string("none (no person seen)"), stops_);
    return Result::Ok();
  }

 private:
  // world -> the robot's base link on /tf_static, once (transient local:
  // late joiners get it). The cell frame is the robot base frame
  // (config/scenes/cell.yaml), so the transform is the identity.
  void PublishStaticTransform(Node& node) {
    msg::TFMessage tf;
    msg::TransformStamped t;
    t.header.stamp = msg::Now();
    t.header.frame_id = "world";
    t.child_frame_id = sim_->robot().link_names.at(0);
    t.transform.rotation.w = 1.0;
    tf.transforms.push_back(t);
    std::string error;
    if (!tf_writer_->Write(tf, &error)) node.log().warn("/tf_static not published: {}", error);
  }

  // Stop at once when any permit is missing, lapsed or a stop; resume when
  // every monitor permits again (their own hysteresis decides when).
  void ApplyPermits(Node& node, int64_t now_ns) {
    // Two writers claiming one monitor: logged once when it begins and once
    // when it ends; the diagnostics keep the latest one.
    for (const safety::WriterConflictEvent& e : gate_->TakeConflictEvents(now_ns)) {
      if (e.raised) {
        ++writer_conflicts_;
        writer_conflict_ = e.description;
        node.log().error("PERMIT WRITER CONFLICT: {}", e.description);
      } else {
        writer_conflict_ += " (cleared: " + e.description + ")";
        node.log().warn("permit writer conflict cleared: {}", e.description);
      }
    }
    const safety::PermitDecision d = gate_->Evaluate(now_ns);
    permit_reason_ = d.reason;
    if (!d.permitted && !sim_->stopped()) {
      sim_->Stop();
      if (ever_permitted_) ++stops_;  // holding still before the first permit is no protective stop
      node.log().warn("PROTECTIVE STOP: {}", d.reason);
    } else if (d.permitted && sim_->stopped()) {
      ever_permitted_ = true;
      sim_->Resume();
      node.log().info("resume: {}", d.reason);
    }
    // ISO/TS 15066 speed reduction: the path time-scaled while a monitor asks.
    if (d.permitted && d.speed_scale < 1.0) slowed_s_ += (now_ns - last_) * 1e-9;
    sim_->SetSpeedScale(d.permitted ? d.speed_scale : 1.0);
  }

  double control_rate_hz_ = 100, publish_rate_hz_ = 50;
  std::unique_ptr<safety::PermitGate> gate_;
  std::string permit_reason_;
  std::string writer_conflict_;  // the latest writer conflict ("" when none yet)
  uint64_t writer_conflicts_ = 0;
  bool ever_permitted_ = false;
  double slowed_s_ = 0.0;  // s the path ran time-scaled (speed reduction)
  std::unique_ptr<RobotSimulator> sim_;
  std::unique_ptr<collision::HumanBodyModel> body_;
  dds::Writer<msg::JointState>* joint_writer_ = nullptr;
  dds::Writer<msg::TFMessage>* tf_writer_ = nullptr;
  int timer_ = 0;
  int64_t last_ = 0;
  uint64_t steps_ = 0, stops_ = 0;
};

}  // namespace
}  // namespace iplan::robot_sim

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv, {"robot_sim", "simulated robot: follows trajectories, obeys protective stops, counts true contacts"},
      [] { return std::make_unique<iplan::robot_sim::RobotSimService>(); });
}
