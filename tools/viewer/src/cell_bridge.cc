#include "iplan/viewer/cell_bridge.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "iplan/framework/node.h"
#include "iplan/framework/topics.h"
#include "iplan/msg/time.h"
#include "iplan/msg/type_table.h"

namespace iplan::viewer {
namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

std::string DdsTopic(const std::string& name) {
  if (name.rfind("rt/", 0) == 0) return name;
  return name.rfind('/', 0) == 0 ? "rt" + name : "rt/" + name;
}
std::string RosTopic(const std::string& dds) { return dds.rfind("rt/", 0) == 0 ? dds.substr(2) : dds; }

std::string ReadSchema(const std::string& dir, const std::string& name) {
  const std::string path = dir + "/" + name + ".json";
  std::ifstream f(path);
  if (!f) throw std::runtime_error("no Foxglove schema " + path + " (run scripts/setup.sh, which builds web/)");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

uint64_t NowNs() { return static_cast<uint64_t>(msg::ToNanoseconds(msg::Now())); }

}  // namespace

std::string RosTypeName(const std::string& dds_type) {
  std::string s = dds_type;
  for (const std::string from : {"::msg::dds_::", "::"}) {
    for (auto at = s.find(from); at != std::string::npos; at = s.find(from)) {
      s.replace(at, from.size(), from == "::" ? "/" : "/msg/");
    }
  }
  if (!s.empty() && s.back() == '_') s.pop_back();
  return s;
}

struct CellBridge::Impl {
  struct Raw {
    std::unique_ptr<dds::AnyReader> reader;
    const msg::TypeEntry* type = nullptr;
    void* sample = nullptr;
    std::size_t channel = 0;
  };

  CellBridgeOptions o;
  Sink sink;
  Wanted wanted;
  std::optional<SceneBuilder> scene;
  std::unique_ptr<framework::Node> node;
  std::vector<Raw> raws;
  std::vector<BridgeChannel> channels;
  std::vector<uint64_t> counts;
  std::size_t scene_channel = 0, cell_channel = 0;
  BridgeStats stats;
  Clock::time_point last_message = Clock::time_point::min(), next_status = Clock::now(), next_static = Clock::now();
  Clock::time_point next_robot = Clock::now(), next_prediction = Clock::now(), next_cloud = Clock::now(),
                    next_human_points = Clock::now();
  bool alive = false;

  ~Impl() {
    for (auto& r : raws) r.type->destroy(r.sample);
  }

  void Emit(std::size_t channel, uint64_t t_ns, const json& j) {
    if (wanted && !wanted(channel)) {
      ++stats.skipped;
      return;
    }
    const std::string text = j.dump();
    if (text.size() > o.max_payload_bytes) {
      ++stats.too_large;
      return;
    }
    ++counts[channel];
    ++stats.forwarded;
    sink(channel, t_ns, text);
  }

  // A scene input the model cannot use is counted and logged by the node
  // (rejected_inputs/scene, first time and every 100th).
  void EmitScene(const json* update) {
    if (!update) {
      stats.scene_rejected = scene->rejected();
      stats.last_scene_rejection = scene->last_rejection();
      node->CountRejection("scene", scene->last_rejection());
      return;
    }
    Emit(scene_channel, NowNs(), *update);
  }

  template <class T, class F>
  void SceneInput(const framework::Topic<T>& topic, F&& draw) {
    node->Subscribe(topic, std::function<void(const T&, const dds::SampleInfo&)>(
                               [this, draw](const T& m, const dds::SampleInfo&) { draw(m); }),
                    framework::SubscribeOptions{false});
  }

  void SubscribeScene() {
    namespace topics = framework::topics;
    SceneInput(topics::JointStates(), [this](const msg::JointState& m) {
      if (Clock::now() < next_robot) return;
      next_robot = Clock::now() + std::chrono::microseconds(static_cast<int64_t>(1e6 / o.robot_rate_hz));
      EmitScene(scene->Robot(m));
    });
    SceneInput(topics::HumanSkeleton(), [this](const msg::HumanSkeleton& m) { EmitScene(scene->Person(m)); });
    SceneInput(topics::HumanPrediction(), [this](const msg::HumanPrediction& m) {
      if (Clock::now() < next_prediction) return;
      next_prediction = Clock::now() + std::chrono::microseconds(static_cast<int64_t>(1e6 / o.prediction_rate_hz));
      EmitScene(scene->Prediction(m));
    });
    SceneInput(topics::RobotTrajectory(), [this](const msg::JointTrajectory& m) { EmitScene(scene->Trajectory(m)); });
    SceneInput(topics::DepthPoints(), [this](const msg::PointCloud2& m) {
      if (Clock::now() < next_cloud) return;
      next_cloud = Clock::now() + std::chrono::milliseconds(200);
      EmitScene(scene->Obstacles(m));
    });
    SceneInput(topics::Obstacles(), [this](const msg::ObstacleArray& m) { EmitScene(scene->Boxes(m)); });
    SceneInput(topics::HumanPoints(), [this](const msg::HumanPoints& m) {
      if (Clock::now() < next_human_points) return;
      next_human_points = Clock::now() + std::chrono::milliseconds(100);
      EmitScene(scene->HumanPoints(m));
    });
    SceneInput(topics::CollisionRisk(), [this](const msg::CollisionRisk& m) {
      const json update = scene->Safety(m);
      EmitScene(&update);
    });
  }

  void AddRawTopics(dds::Participant& p) {
    std::vector<framework::TopicDescription> chosen;
    const auto all = framework::topics::All();
    if (o.topics.empty()) chosen = all;
    for (const auto& name : o.topics) {
      auto it = std::find_if(all.begin(), all.end(), [&](const auto& t) { return t.name == DdsTopic(name); });
      if (it == all.end()) throw std::invalid_argument("'" + name + "' is not an iplan topic (see iplan topic list --all)");
      chosen.push_back(*it);
    }
    for (const auto& t : chosen) {
      Raw r;
      r.type = msg::FindType(t.type);
      if (!r.type) throw std::runtime_error("topic " + t.name + " has unknown type " + t.type);
      r.reader = std::make_unique<dds::AnyReader>(p, t.name, t.type, t.qos.RelaxedFor());
      r.sample = r.type->create();
      r.channel = channels.size();
      channels.push_back({RosTopic(t.name), RosTypeName(t.type), r.type->json_schema().dump()});
      raws.push_back(std::move(r));
    }
  }

  void Status() {
    const auto now = Clock::now();
    const double age = last_message == Clock::time_point::min() ? -1.0
                                                                 : std::chrono::duration<double>(now - last_message).count();
    alive = age >= 0 && age <= o.alive_after;
    Emit(cell_channel, NowNs(),
         {{"alive", alive}, {"last_message_age_s", age}, {"alive_after_s", o.alive_after},
          {"status_period_s", o.status_period}, {"forwarded", stats.forwarded}, {"scene_rejected", stats.scene_rejected}});
  }
};

CellBridge::CellBridge(dds::Participant& participant, std::optional<SceneBuilder> scene, CellBridgeOptions options,
                       Sink sink, Wanted wanted)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.o = std::move(options);
  s.sink = std::move(sink);
  s.wanted = std::move(wanted);
  s.scene = std::move(scene);
  s.AddRawTopics(participant);
  if (s.scene) {
    s.scene_channel = s.channels.size();
    s.channels.push_back({kSceneTopic, "foxglove.SceneUpdate", ReadSchema(s.o.schema_dir, "foxglove.SceneUpdate")});
  }
  s.cell_channel = s.channels.size();
  const json cell_schema = {{"type", "object"},
                            {"title", "iplan viewer cell status"},
                            {"properties",
                             {{"alive", {{"type", "boolean"}}},
                              {"last_message_age_s", {{"type", "number"}}},
                              {"alive_after_s", {{"type", "number"}}},
                              {"status_period_s", {{"type", "number"}}},
                              {"forwarded", {{"type", "integer"}}},
                              {"scene_rejected", {{"type", "integer"}}}}}};
  s.channels.push_back({kCellTopic, "iplan_viewer/CellStatus", cell_schema.dump()});
  s.counts.assign(s.channels.size(), 0);
  framework::NodeOptions no;
  no.diagnostics_period = 0;  // passive: the viewer publishes nothing into the cell
  s.node = std::make_unique<framework::Node>("viewer", participant, no);
  if (s.scene) s.SubscribeScene();
}

CellBridge::~CellBridge() = default;

const std::vector<BridgeChannel>& CellBridge::channels() const { return impl_->channels; }
const std::vector<uint64_t>& CellBridge::counts() const { return impl_->counts; }
BridgeStats CellBridge::stats() const { return impl_->stats; }

void CellBridge::SpinOnce(std::chrono::nanoseconds max_wait) {
  Impl& s = *impl_;
  s.node->SpinOnce(max_wait);
  dds::SampleInfo info;
  for (auto& r : s.raws) {
    r.reader->TakeEvents();
    while (r.reader->TakeAny(r.sample, &info)) {
      s.last_message = Clock::now();
      if (s.wanted && !s.wanted(r.channel)) {
        ++s.stats.skipped;
        continue;
      }
      s.Emit(r.channel, NowNs(), r.type->to_json(r.sample));
    }
  }
  const auto now = Clock::now();
  if (s.scene && now >= s.next_static) {
    s.next_static = now + std::chrono::seconds(1);
    s.Emit(s.scene_channel, NowNs(), s.scene->Static(msg::Now()));
  }
  if (now >= s.next_status) {
    s.next_status = now + std::chrono::microseconds(static_cast<int64_t>(s.o.status_period * 1e6));
    s.Status();
  }
}

}  // namespace iplan::viewer
