#include "iplan/framework/topics.h"

namespace iplan::framework::topics {
namespace {
using std::chrono::milliseconds;
using Q = dds::QosProfile;
}  // namespace

Topic<msg::HumanSkeleton> HumanSkeleton() {
  // Any provider may publish skeletons (perception is swappable).
  return {"rt/iplan/human/skeleton", Q::SensorStream(milliseconds(150), milliseconds(300)), {}, true};
}
Topic<msg::HumanSkeleton> HumanTruth() {
  return {"rt/iplan/sim/human_truth", Q::SensorStream(milliseconds(150), milliseconds(300)), {}, true};
}
Topic<msg::PointCloud2> DepthPoints() {
  // Any provider may publish clouds (the depth camera is swappable).
  return {"rt/iplan/depth/points", Q::SensorStream(milliseconds(200), milliseconds(300))};
}
Topic<msg::ObstacleArray> Obstacles() {
  return {"rt/iplan/obstacles", Q::SensorStream(milliseconds(1000), milliseconds(1000)), {"iplan-cloud"}, true};
}
Topic<msg::HumanPoints> HumanPoints() {
  return {"rt/iplan/human/points", Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-cloud"}, true};
}
Topic<msg::ActionBelief> ActionBelief() {
  return {"rt/iplan/human/action_belief", Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-intent"}};
}
Topic<msg::HumanPrediction> HumanPrediction() {
  return {"rt/iplan/human/prediction", Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-intent"}, true};
}
Topic<msg::JointState> JointStates() {
  return {"rt/joint_states", Q::SensorStream(milliseconds(100), milliseconds(300))};
}
Topic<msg::JointTrajectory> RobotTrajectory() {
  return {"rt/iplan/robot/trajectory", Q::LatchedState(milliseconds(300), milliseconds(300)), {"iplan-trajopt"}};
}
Topic<msg::TaskCommand> TaskCommand() {
  return {"rt/iplan/task/command", Q::Command(milliseconds(1000)), {"iplan-supervisor"}};
}
Topic<msg::TaskOutcome> TaskOutcome() {
  return {"rt/iplan/task/outcome", Q::Command(milliseconds(1000)), {"iplan-trajopt"}};
}
Topic<msg::PlanStatus> PlanStatus() {
  return {"rt/iplan/robot/plan_status", Q::SensorStream(milliseconds(300), milliseconds(300)), {"iplan-trajopt"}};
}
Topic<msg::CollisionRisk> CollisionRisk() {
  return {"rt/iplan/collision_risk", Q::SensorStream(milliseconds(200), milliseconds(300)), {"iplan-collision_risk"}};
}
Topic<msg::SafetyPermit> SafetyPermit() {
  // Deadline and lease well above the permit period (50 ms); the robot side
  // judges freshness itself, from each permit's validity.
  return {"rt/iplan/safety/permit", Q::SensorStream(milliseconds(200), milliseconds(300)),
          {"iplan-supervisor", "iplan-collision_risk"}};
}
Topic<msg::DiagnosticArray> Diagnostics() {
  Q q = Q::Command(milliseconds(3000));
  q.name = "status";
  return {"rt/diagnostics", q};
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
      Describe(SafetyPermit(), "permission to move, re-published every period (supervisor, collision risk)"),
      Describe(Diagnostics(), "per-service diagnostics (every service)"),
  };
}

}  // namespace iplan::framework::topics
