// iplan-perception: publishes tracked human skeletons from a provider.
// Provider "synthetic": a simulated person (core/synthetic_person.h).
#include <chrono>

#include "core/synthetic_person.h"
#include "iplan/framework/service.h"

namespace iplan::perception {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class PerceptionService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    config.Read("provider", &provider_, framework::OneOf({"synthetic"}));
    config.Read("rate_hz", &rate_hz_, framework::InRange(0.5, 1000.0));
    config.Read("frame_id", &frame_id_);
    config.Read("publish_truth", &publish_truth_);
    ConfigSection syn = config.Section("synthetic");
    std::vector<double> torso = {params_.torso_W.x(), params_.torso_W.y(), params_.torso_W.z()};
    std::vector<double> target = {params_.reach_target_W.x(), params_.reach_target_W.y(), params_.reach_target_W.z()};
    auto three = [](const std::vector<double>& v) {
      return v.size() == 3 ? std::string() : "must have 3 numbers (x, y, z in m)";
    };
    if (syn.Read("torso", &torso, framework::Check<std::vector<double>>(three))) {
      params_.torso_W = {torso[0], torso[1], torso[2]};
    }
    if (syn.Read("reach_target", &target, framework::Check<std::vector<double>>(three))) {
      params_.reach_target_W = {target[0], target[1], target[2]};
    }
    syn.Read("facing_yaw", &params_.facing_yaw);
    syn.Read("reach_period", &params_.reach_period, framework::Positive<double>());
    syn.Read("noise_stddev", &params_.noise_stddev, framework::NonNegative<double>());
    int seed = static_cast<int>(params_.seed);
    syn.Read("seed", &seed, framework::NonNegative<int>());
    params_.seed = static_cast<uint64_t>(seed);
    if (const std::string why = params_.Validate(); !why.empty()) return Result::Fail(why);
    person_ = std::make_unique<SyntheticPerson>(params_);
    skeleton_writer_ = &node.Advertise(framework::topics::HumanSkeleton());
    if (publish_truth_) truth_writer_ = &node.Advertise(framework::topics::HumanTruth());
    node.SetDiagnosticValue("provider", provider_);
    return Result::Ok();
  }

  Result OnActivate(Node& node) override {
    start_ = std::chrono::system_clock::now();
    timer_ = node.AddTimer(std::chrono::nanoseconds(static_cast<int64_t>(1e9 / rate_hz_)), [this, &node] { Tick(node); });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    node.CancelTimer(timer_);
    return Result::Ok();
  }

 private:
  msg::HumanSkeleton ToMessage(const std::vector<JointSample>& joints, const msg::Time& stamp) const {
    msg::HumanSkeleton s;
    s.header.stamp = stamp;
    s.header.frame_id = frame_id_;
    s.body_id = 1;
    s.confidence = 1.0;
    s.joints.reserve(joints.size());
    for (const auto& j : joints) {
      msg::HumanJoint m;
      m.name = j.name;
      m.position.x = j.position_W.x();
      m.position.y = j.position_W.y();
      m.position.z = j.position_W.z();
      m.covariance = {j.variance, 0, 0, 0, j.variance, 0, 0, 0, j.variance};
      m.confidence = 1.0;
      s.joints.push_back(std::move(m));
    }
    return s;
  }

  void Tick(Node& node) {
    const auto tick_start = std::chrono::steady_clock::now();
    const auto now = std::chrono::system_clock::now();
    const double t = std::chrono::duration<double>(now - start_).count();
    const msg::Time stamp = msg::Now();
    std::string err;
    if (!skeleton_writer_->Write(ToMessage(person_->Observe(t), stamp), &err)) {
      node.log().warn("skeleton not published: {}", err);
    }
    if (truth_writer_) truth_writer_->Write(ToMessage(person_->TruePose(t), stamp));
    ++published_;
    node.SetDiagnosticValue("published", std::to_string(published_));
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - tick_start).count());
  }

  std::string provider_ = "synthetic";
  double rate_hz_ = 30;
  std::string frame_id_ = "world";
  bool publish_truth_ = false;
  SyntheticPersonParams params_;
  std::unique_ptr<SyntheticPerson> person_;
  dds::Writer<msg::HumanSkeleton>* skeleton_writer_ = nullptr;
  dds::Writer<msg::HumanSkeleton>* truth_writer_ = nullptr;
  std::chrono::system_clock::time_point start_;
  int timer_ = 0;
  uint64_t published_ = 0;
};

}  // namespace
}  // namespace iplan::perception

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv, {"perception", "publishes tracked human skeletons from a provider (synthetic person)"},
      [] { return std::make_unique<iplan::perception::PerceptionService>(); });
}
