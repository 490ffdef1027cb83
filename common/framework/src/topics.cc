#include "iplan/framework/topics.h"

#include <algorithm>
#include <cctype>
#include <mutex>
#include <set>
#include <stdexcept>

namespace iplan::framework::topics {
namespace {
using std::chrono::milliseconds;
using Q = dds::QosProfile;

// The catalogue's wire names, before remapping.
const std::vector<std::string>& CatalogueNames() {
  static const std::vector<std::string> kNames = {
      "rt/iplan/human/skeleton", "rt/iplan/sim/human_truth", "rt/iplan/depth/points", "rt/iplan/depth/image",
      "rt/iplan/obstacles",
      "rt/iplan/human/points", "rt/iplan/human/action_belief", "rt/iplan/human/prediction", "rt/joint_states",
      "rt/iplan/robot/trajectory", "rt/iplan/task/command", "rt/iplan/task/outcome", "rt/iplan/robot/plan_status",
      "rt/iplan/collision_risk", "rt/iplan/safety/permit/supervisor", "rt/iplan/safety/permit/collision_risk",
      "rt/diagnostics", "rt/tf_static"};
  return kNames;
}

struct Remaps {
  std::mutex mu;
  std::map<std::string, std::string> wire;  // catalogue wire name -> remapped wire name
};
Remaps& TheRemaps() {
  static Remaps r;
  return r;
}

// `catalogue` (a wire name of CatalogueNames()) after the remappings.
std::string Named(const std::string& catalogue) {
  Remaps& r = TheRemaps();
  std::lock_guard<std::mutex> lock(r.mu);
  auto it = r.wire.find(catalogue);
  return it == r.wire.end() ? catalogue : it->second;
}

// Why `name` (fully qualified, "/a/b") is not a valid ROS 2 topic name, or "".
std::string InvalidRosName(const std::string& name) {
  if (name.size() < 2 || name[0] != '/') return "'" + name + "' is not a topic name";
  if (name.size() > 250) return "'" + name + "' is longer than 250 characters";
  if (name.back() == '/') return "'" + name + "' ends with '/'";
  bool token_start = true;
  for (std::size_t i = 1; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c == '/') {
      if (token_start) return "'" + name + "' has an empty token ('//')";
      token_start = true;
      continue;
    }
    if (!std::isalnum(c) && c != '_') return "'" + name + "' has '" + std::string(1, name[i]) + "' (allowed: A-Z a-z 0-9 _ /)";
    if (token_start && std::isdigit(c)) return "'" + name + "' has a token starting with a digit";
    token_start = false;
  }
  return "";
}

std::string Qualified(const std::string& name) { return !name.empty() && name[0] != '/' ? "/" + name : name; }
}  // namespace

bool ParseRemapRule(const std::string& rule, std::string* from, std::string* to, std::string* error) {
  const auto pos = rule.find(":=");
  if (pos == std::string::npos || rule.find(":=", pos + 2) != std::string::npos) {
    *error = "remap '" + rule + "' is not FROM:=TO";
    return false;
  }
  *from = Qualified(rule.substr(0, pos));
  *to = Qualified(rule.substr(pos + 2));
  for (const std::string* n : {from, to}) {
    if (std::string why = InvalidRosName(*n); !why.empty()) {
      *error = "remap '" + rule + "': " + why;
      return false;
    }
  }
  return true;
}

std::string SetRemappings(const std::map<std::string, std::string>& from_to) {
  std::map<std::string, std::string> wire;
  for (const auto& [from_ros, to_ros] : from_to) {
    const std::string from = "rt" + Qualified(from_ros), to = "rt" + Qualified(to_ros);
    if (std::string why = InvalidRosName(Qualified(to_ros)); !why.empty()) return "remap of " + from_ros + ": " + why;
    const auto& names = CatalogueNames();
    if (std::find(names.begin(), names.end(), from) == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n.substr(2);
      return "remap: '" + from_ros + "' is not a topic of the catalogue (" + known + ")";
    }
    if (from != to) wire[from] = to;
  }
  std::set<std::string> used;
  for (const std::string& n : CatalogueNames()) {
    auto it = wire.find(n);
    const std::string name = it == wire.end() ? n : it->second;
    if (!used.insert(name).second) return "remap: two topics would be named " + name.substr(2);
  }
  Remaps& r = TheRemaps();
  std::lock_guard<std::mutex> lock(r.mu);
  r.wire = std::move(wire);
  return "";
}

std::string CatalogueName(const std::string& dds_name) {
  Remaps& r = TheRemaps();
  std::lock_guard<std::mutex> lock(r.mu);
  for (const auto& [from, to] : r.wire) {
    if (to == dds_name) return from;
  }
  return dds_name;
}

Topic<msg::HumanSkeleton> HumanSkeleton() {
  // Any provider may publish skeletons (perception is swappable).
  return {Named("rt/iplan/human/skeleton"), Q::SensorStream(milliseconds(150), milliseconds(300)), {}, true};
}
Topic<msg::HumanSkeleton> HumanTruth() {
  return {Named("rt/iplan/sim/human_truth"), Q::SensorStream(milliseconds(150), milliseconds(300)), {}, true};
}
Topic<msg::PointCloud2> DepthPoints() {
  // Any provider may publish clouds (the depth camera is swappable).
  return {Named("rt/iplan/depth/points"), Q::SensorStream(milliseconds(200), milliseconds(300))};
}
Topic<msg::Image> DepthImage() {
  // Any provider may publish depth images (the depth camera is swappable).
  return {Named("rt/iplan/depth/image"), Q::SensorStream(milliseconds(200), milliseconds(300))};
}
Topic<msg::CameraInfo> DepthCameraInfo() {
  // Whoever publishes the depth images publishes their calibration.
  return {Named("rt/iplan/depth/camera_info"), Q::SensorStream(milliseconds(200), milliseconds(300))};
}
Topic<msg::ObstacleArray> Obstacles() {
  return {Named("rt/iplan/obstacles"), Q::SensorStream(milliseconds(1000), milliseconds(1000)), {"iplan-cloud"}, true};
}
Topic<msg::HumanPoints> HumanPoints() {
  return {Named("rt/iplan/human/points"), Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-cloud"}, true};
}
Topic<msg::ActionBelief> ActionBelief() {
  return {Named("rt/iplan/human/action_belief"), Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-intent"}};
}
Topic<msg::HumanPrediction> HumanPrediction() {
  return {Named("rt/iplan/human/prediction"), Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-intent"}, true};
}
Topic<msg::JointState> JointStates() {
  return {Named("rt/joint_states"), Q::SensorStream(milliseconds(100), milliseconds(300))};
}
Topic<msg::JointTrajectory> RobotTrajectory() {
  return {Named("rt/iplan/robot/trajectory"), Q::LatchedState(milliseconds(300), milliseconds(300)), {"iplan-trajopt"}};
}
Topic<msg::TaskCommand> TaskCommand() {
  return {Named("rt/iplan/task/command"), Q::Command(milliseconds(1000)), {"iplan-supervisor"}};
}
Topic<msg::TaskOutcome> TaskOutcome() {
  return {Named("rt/iplan/task/outcome"), Q::Command(milliseconds(1000)), {"iplan-trajopt"}};
}
Topic<msg::PlanStatus> PlanStatus() {
  return {Named("rt/iplan/robot/plan_status"), Q::SensorStream(milliseconds(300), milliseconds(300)), {"iplan-trajopt"}};
}
Topic<msg::CollisionRisk> CollisionRisk() {
  return {Named("rt/iplan/collision_risk"), Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-collision_risk"}};
}
Topic<msg::SafetyPermit> SafetyPermit(const std::string& monitor) {
  const std::string prefix = "iplan-";
  std::string token = monitor.rfind(prefix, 0) == 0 ? monitor.substr(prefix.size()) : monitor;
  std::replace_if(token.begin(), token.end(), [](char c) { return c == '-' || c == '.'; }, '_');
  if (const std::string why = InvalidRosName("/iplan/safety/permit/" + token); !why.empty() || monitor.empty()) {
    throw std::invalid_argument("monitor '" + monitor + "' gives no permit topic: " +
                                (why.empty() ? std::string("empty name") : why));
  }
  // Deadline and lease well above the permit period (50 ms); the robot side
  // judges freshness itself, from each permit's validity.
  return {Named("rt/iplan/safety/permit/" + token), Q::SensorStream(milliseconds(200), milliseconds(300)), {monitor}};
}
Topic<msg::SafetyPermit> SupervisorPermit() { return SafetyPermit("iplan-supervisor"); }
Topic<msg::SafetyPermit> CollisionRiskPermit() { return SafetyPermit("iplan-collision_risk"); }
Topic<msg::DiagnosticArray> Diagnostics() {
  Q q = Q::Command(milliseconds(3000));
  q.name = "status";
  return {Named("rt/diagnostics"), q};
}

Topic<msg::TFMessage> TfStatic() {
  // tf2's static broadcaster: reliable, transient local, keep last 1; no
  // deadline (written once), a lease so a reader sees the writer go.
  Q q = Q::LatchedState(std::chrono::nanoseconds(0), milliseconds(3000));
  q.name = "static";
  return {Named("rt/tf_static"), q};
}

namespace {
template <class T>
TopicDescription Describe(const Topic<T>& t, const char* what) {
  return {t.name, msg::TypeName<T>::kDds, t.qos, what};
}
}  // namespace

std::vector<TopicDescription> All() {
  return {
      Describe(HumanSkeleton(), "tracked human skeletons (perception)"),
      Describe(HumanTruth(), "true pose of the simulated person (simulation only)"),
      Describe(DepthPoints(), "depth camera point cloud, sensor frame (perception or any camera driver)"),
      Describe(DepthImage(), "depth camera image, 16UC1 mm or 32FC1 m (perception or any camera driver)"),
      Describe(DepthCameraInfo(), "the depth camera's calibration, beside each image (perception or a camera driver)"),
      Describe(Obstacles(), "static unknown obstacles as boxes (cloud)"),
      Describe(HumanPoints(), "points of moving objects (people) with sensor noise (cloud)"),
      Describe(ActionBelief(), "probability of each human action (intent)"),
      Describe(HumanPrediction(), "predicted human motion, Gaussian mixture over actions (intent)"),
      Describe(JointStates(), "robot joint state (robot or simulator)"),
      Describe(RobotTrajectory(), "trajectory the robot executes (trajectory optimisation)"),
      Describe(TaskCommand(), "robot task commands (supervisor)"),
      Describe(TaskOutcome(), "robot task outcomes (trajectory optimisation)"),
      Describe(PlanStatus(), "one status per replanning cycle, with end-to-end latency (trajectory optimisation)"),
      Describe(CollisionRisk(), "collision bound and separation monitoring (collision risk)"),
      Describe(SupervisorPermit(), "the supervisor's permission to move, re-published every period"),
      Describe(CollisionRiskPermit(), "collision risk's permission to move, re-published every period"),
      Describe(Diagnostics(), "per-service diagnostics (every service)"),
      Describe(TfStatic(), "static transforms: world -> robot base (robot simulator)"),
  };
}

}  // namespace iplan::framework::topics
