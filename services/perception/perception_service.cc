// iplan-perception: publishes tracked human skeletons from a provider.
// Provider "synthetic": a simulated person (core/synthetic_person.h).
// Provider "replay": recorded sequences from a skeleton CSV file, at their
// recorded times (core/skeleton_replay.h).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <vector>

#include "services/perception/core/skeleton_replay.h"
#include "depth_source.h"
#include "iplan/framework/service.h"
#include "perception_settings.h"

namespace iplan::perception {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class PerceptionService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    PerceptionSettings settings;
    core::ReadParams(config, &settings);  // every range: PerceptionSettings::Validate
    if (!config.Problems().empty()) return Result::Ok();  // reported by the configuration check
    provider_ = settings.provider;
    rate_hz_ = settings.rate_hz;
    frame_id_ = settings.frame_id;
    publish_truth_ = settings.publish_truth;
    publish_skeleton_ = settings.publish_skeleton;
    start_ = std::chrono::system_clock::now();
    params_ = settings.synthetic.Person();
    script_start_ = settings.synthetic.Start();
    const std::vector<SyntheticPersonParams> others = settings.synthetic.MorePeople();
    if (Result r = ConfigureReplay(config, settings.replay); !r.ok) return r;
    if (provider_ == "synthetic") {
      try {
        // Body 1 is the first person, bodies 2, 3, ... perception.synthetic.more_people.
        people_.push_back(std::make_unique<SyntheticPerson>(params_));
        for (const SyntheticPersonParams& p : others) people_.push_back(std::make_unique<SyntheticPerson>(p));
      } catch (const std::exception& e) {
        return Result::Fail(config.file() + ": key 'perception.synthetic': " + e.what());
      }
      node.SetDiagnosticValue("people", std::to_string(people_.size()));
      if (script_start_ == ScriptStart::kEpisodes) {
        // The person starts their part of the task with each episode.
        using SI = const dds::SampleInfo&;
        node.Subscribe(framework::topics::TaskCommand(),
                       std::function<void(const msg::TaskCommand&, SI)>([this, &node](const msg::TaskCommand& m, SI) {
                         if (m.command != msg::TaskCommand::START || m.episode == 0 || m.episode == episode_) return;
                         episode_ = m.episode;
                         for (auto& person : people_) person->StartScript(Seconds());
                         node.log().info("episode {}: the person starts their script", episode_);
                       }),
                       framework::SubscribeOptions{false});
      }
    }
    // Without the skeleton stream the person is seen (if at all) by the depth
    // camera only: a person the skeleton tracker lost.
    if (publish_skeleton_) skeleton_writer_ = &node.Advertise(framework::topics::HumanSkeleton());
    node.SetDiagnosticValue("publish_skeleton", publish_skeleton_ ? "true" : "false");
    if (publish_truth_) truth_writer_ = &node.Advertise(framework::topics::HumanTruth());
    node.SetDiagnosticValue("provider", provider_);
    return depth_.Configure(config, settings.depth, node);  // the depth camera, if any
  }

  Result OnActivate(Node& node) override {
    start_ = std::chrono::system_clock::now();
    depth_.Activate(node, [this] {
      std::vector<std::vector<JointSample>> poses;
      for (const auto& person : people_) poses.push_back(person->TruePose(Seconds()));
      return poses;
    });
    if (replay_) {
      start_ns_ = msg::ToNanoseconds(msg::Now());
      timer_ = node.AddTimer(kReplayPoll, [this, &node] { ReplayTick(node); });
      return Result::Ok();
    }
    timer_ = node.AddTimer(std::chrono::nanoseconds(static_cast<int64_t>(1e9 / rate_hz_)), [this, &node] { Tick(node); });
    return Result::Ok();
  }

  Result OnDeactivate(Node& node) override {
    node.CancelTimer(timer_);
    depth_.Deactivate(node);
    return Result::Ok();
  }

 private:
  // Frames are published within this period of their play time.
  static constexpr std::chrono::milliseconds kReplayPoll{5};

  // Loads perception.replay's file (provider replay only); a joint_map name
  // that the file does not have is refused.
  Result ConfigureReplay(ConfigSection& config, const ReplaySettings& settings) {
    if (provider_ != "replay") return Result::Ok();
    const SkeletonReplayParams p = settings.ToParams(config.ResolvePath(settings.file));
    try {
      intent::SkeletonDataset data = intent::LoadSkeletonCsv(p.file);
      for (const auto& [name, to] : p.joint_map) {
        if (std::find(data.joint_names.begin(), data.joint_names.end(), name) == data.joint_names.end()) {
          return Result::Fail(config.file() + ": key 'perception.replay.joint_map." + name + "': " + p.file +
                              " has no joint '" + name + "'");
        }
      }
      replay_ = std::make_unique<SkeletonReplay>(p, std::move(data));
    } catch (const std::exception& e) {
      return Result::Fail(config.file() + ": key 'perception.replay': " + e.what());
    }
    return Result::Ok();
  }

  void ReplayTick(Node& node) {
    const auto tick_start = std::chrono::steady_clock::now();
    const double now = 1e-9 * static_cast<double>(msg::ToNanoseconds(msg::Now()) - start_ns_);
    while (replay_->Next(now, &frame_)) {
      const msg::Time stamp = msg::TimeFromNanoseconds(start_ns_ + std::llround(frame_.play_time * 1e9));
      std::string err;
      if (skeleton_writer_ && !skeleton_writer_->Write(ToMessage(frame_.joints, stamp, frame_.body_id), &err)) {
        node.log().warn("skeleton not published: {}", err);
      }
      ++published_;
      if (frame_.sequence_id != sequence_) {
        sequence_ = frame_.sequence_id;
        node.SetDiagnosticValue("replay_sequence", sequence_ + " (" + frame_.action + ")");
      }
    }
    node.SetDiagnosticValue("published", std::to_string(published_));
    if (replay_->finished() && !announced_end_) {
      node.log().info("replay finished after {} skeletons", published_);
      node.SetDiagnosticValue("replay_finished", "true");
      announced_end_ = true;
    }
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - tick_start).count());
  }

  msg::HumanSkeleton ToMessage(const std::vector<JointSample>& joints, const msg::Time& stamp,
                               uint32_t body_id = 1) const {
    msg::HumanSkeleton s;
    s.header.stamp = stamp;
    s.header.frame_id = frame_id_;
    s.body_id = body_id;
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

  double Seconds() const { return std::chrono::duration<double>(std::chrono::system_clock::now() - start_).count(); }

  void Tick(Node& node) {
    const auto tick_start = std::chrono::steady_clock::now();
    const double t = Seconds();
    const msg::Time stamp = msg::Now();
    for (std::size_t i = 0; i < people_.size(); ++i) {
      const uint32_t body_id = static_cast<uint32_t>(i + 1);
      std::string err;
      if (skeleton_writer_ && !skeleton_writer_->Write(ToMessage(people_[i]->Observe(t), stamp, body_id), &err)) {
        node.log().warn("skeleton of body {} not published: {}", body_id, err);
      }
      if (truth_writer_) truth_writer_->Write(ToMessage(people_[i]->TruePose(t), stamp, body_id));
      ++published_;
    }
    node.SetDiagnosticValue("published", std::to_string(published_));
    const std::string& action = people_.front()->ActionAt(t);
    if (action != action_) {
      action_ = action;
      node.SetDiagnosticValue("action", action_);  // the simulated person's true action
    }
    node.RecordCycleTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - tick_start).count());
  }

  std::string provider_ = "synthetic";
  double rate_hz_ = 30;
  std::string frame_id_ = "world";
  bool publish_truth_ = false;
  bool publish_skeleton_ = true;
  SyntheticPersonParams params_;
  std::vector<std::unique_ptr<SyntheticPerson>> people_;  // body i + 1
  ScriptStart script_start_ = ScriptStart::kLoop;
  uint32_t episode_ = 0;
  std::string action_;
  dds::Writer<msg::HumanSkeleton>* skeleton_writer_ = nullptr;
  dds::Writer<msg::HumanSkeleton>* truth_writer_ = nullptr;
  std::chrono::system_clock::time_point start_;
  int timer_ = 0;
  uint64_t published_ = 0;
  std::unique_ptr<SkeletonReplay> replay_;
  ReplayFrame frame_;
  int64_t start_ns_ = 0;
  std::string sequence_;
  bool announced_end_ = false;
  DepthSource depth_;
};

}  // namespace
}  // namespace iplan::perception

int main(int argc, char** argv) {
  return iplan::framework::RunService(
      argc, argv, {"perception", "publishes tracked human skeletons from a provider (synthetic person or recorded replay)"},
      [] { return std::make_unique<iplan::perception::PerceptionService>(); });
}
