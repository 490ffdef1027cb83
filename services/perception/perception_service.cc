// iplan-perception: publishes tracked human skeletons from a provider.
// Provider "synthetic": a simulated person (core/synthetic_person.h).
// Provider "replay": recorded sequences from a skeleton CSV file, at their
// recorded times (core/skeleton_replay.h).
#include <chrono>
#include <filesystem>
#include <vector>

#include "core/skeleton_replay.h"
#include "depth_source.h"
#include "iplan/framework/service.h"
#include "synthetic_config.h"

namespace iplan::perception {
namespace {

using framework::ConfigSection;
using framework::Node;
using framework::Result;

class PerceptionService : public framework::Service {
 public:
  Result OnConfigure(ConfigSection& config, Node& node) override {
    config.Read("provider", &provider_, framework::OneOf({"synthetic", "replay"}));
    config.Read("rate_hz", &rate_hz_, framework::InRange(0.5, 1000.0));
    config.Read("frame_id", &frame_id_);
    config.Read("publish_truth", &publish_truth_);
    config.Read("publish_skeleton", &publish_skeleton_);
    start_ = std::chrono::system_clock::now();
    ConfigSection syn = config.Section("synthetic");
    std::vector<SyntheticPersonParams> others;
    params_ = ReadSyntheticPerson(syn, &script_start_, &others);
    if (Result r = ConfigureReplay(config); !r.ok) return r;
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
    return depth_.Configure(config.Section("depth"), node);  // the depth camera, if any
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

  // Reads perception.replay (its scalar keys always, so that switching the
  // provider keeps the file valid; joint_map only for provider replay, since
  // its keys are the file's joint names) and loads the file.
  Result ConfigureReplay(ConfigSection& config) {
    ConfigSection rep = config.Section("replay");
    SkeletonReplayParams p;
    rep.Read("file", &p.file);
    rep.Read("sequences", &p.sequences);
    rep.Read("subjects", &p.subjects);
    rep.Read("loop", &p.loop);
    rep.Read("rate", &p.rate, framework::Positive<double>());
    rep.Read("pause", &p.pause, framework::Positive<double>());
    rep.Read("start_delay", &p.start_delay, framework::NonNegative<double>());
    ConfigSection tf = rep.Section("transform");
    std::vector<double> translation = {0, 0, 0}, matrix;
    double yaw = 0;
    const bool has_xyz = tf.Read("translation", &translation, framework::Check<std::vector<double>>(
        [](const std::vector<double>& v) { return v.size() == 3 ? "" : "must have 3 numbers (x, y, z in m)"; }));
    const bool has_yaw = tf.Read("yaw", &yaw);
    if (tf.Read("matrix", &matrix)) {
      if (has_xyz || has_yaw) {
        tf.AddError("matrix", "give either matrix or translation/yaw, not both");
      } else if (const std::string why = TransformFromMatrix(matrix, &p.X_WS); !why.empty()) {
        tf.AddError("matrix", why);
      }
    } else {
      p.X_WS = TransformFromTranslationYaw({translation[0], translation[1], translation[2]}, yaw);
    }
    if (provider_ != "replay") return Result::Ok();
    if (p.file.empty()) {
      rep.AddError("file", "required with provider replay");
      return Result::Ok();  // reported by the configuration check
    }
    p.file = config.ResolvePath(p.file);
    try {
      intent::SkeletonDataset data = intent::LoadSkeletonCsv(p.file);
      ConfigSection map = rep.Section("joint_map");
      for (const std::string& name : data.joint_names) {
        std::string to;
        if (map.Read(name, &to)) p.joint_map[name] = to;
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
